// Hostile and broken clients against a real `vantage learner` process while
// a real `vantage actor` trains with it: a hand-written gRPC client tries
// each way one client could wreck a run, and after each the actor must
// still be training (new policy versions appear) and the learner must stay
// within its memory and thread bounds.

#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>
#include <signal.h>

#include <chrono>
#include <fstream>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "proto/vantage.grpc.pb.h"
#include "proto/vantage.pb.h"
#include "tests/deploy/cli/run_vantage.h"
#include "tests/fakes/http_get.h"
#include "tests/fakes/learner_process.h"
#include "tests/fakes/pendulum_spec.h"
#include "tests/fakes/run_files.h"

namespace vantage {
namespace {

using ::testing::AnyOf;
using ::testing::HasSubstr;

constexpr char kToken[] = "adversarial-test-token";
constexpr int64_t kObs = kPendulumObservationSize;
constexpr int64_t kSegmentSteps = 8;
// How much the learner's resident memory may grow over a whole attack: the
// 200 MiB registrations alone once took it from 186 MB to a 2.7 GB peak.
// Growth of 163 MB was measured once under ctest -j2 (allocator retention
// of gRPC's buffers varies run to run), hence 250 MB rather than 150.
constexpr int64_t kRssBoundBytes = 250 << 20;
// What one refused message may add to the learner's peak memory: gRPC
// 1.51 holds a whole message before it checks its size.
constexpr int64_t kPeakPerMessageBytes = 256 << 20;

pb::Tensor FloatTensor(std::vector<int64_t> shape, float value) {
  pb::Tensor tensor;
  tensor.set_dtype(pb::Tensor::FLOAT32);
  int64_t n = 1;
  for (int64_t d : shape) {
    tensor.add_shape(d);
    n *= d;
  }
  std::vector<float> values(n, value);
  tensor.set_data(std::string(reinterpret_cast<const char*>(values.data()),
                              values.size() * sizeof(float)));
  return tensor;
}

pb::Tensor BoolTensor(int64_t n) {
  pb::Tensor tensor;
  tensor.set_dtype(pb::Tensor::BOOL);
  tensor.add_shape(n);
  tensor.set_data(std::string(n, '\0'));
  return tensor;
}

// A well-formed segment of `actor_id`'s slot 0 with no episode end.
pb::Segment HonestSegment(int64_t actor_id, int64_t version, int64_t sequence) {
  pb::Segment segment;
  segment.set_actor_id(actor_id);
  segment.set_env_slot(0);
  segment.set_sequence(sequence);
  segment.set_policy_version(version);
  *segment.mutable_observations() =
      FloatTensor({kSegmentSteps + 1, kObs}, 0.1f);
  *segment.mutable_actions() = FloatTensor({kSegmentSteps, 1}, 0.5f);
  *segment.mutable_rewards() = FloatTensor({kSegmentSteps}, 1.0f);
  *segment.mutable_terminated() = BoolTensor(kSegmentSteps);
  *segment.mutable_truncated() = BoolTensor(kSegmentSteps);
  *segment.mutable_final_observations() = FloatTensor({0, kObs}, 0.0f);
  *segment.mutable_behaviour_log_probs() = FloatTensor({kSegmentSteps}, -1.0f);
  return segment;
}

struct Registered {
  int64_t actor_id = -1;
  std::string session;
  int64_t version = 0;
};

class AdversarialTest : public ::testing::Test {
 protected:
  void SetUp() override {
    token_file_ = new std::string(WriteTemp("token", kToken));
    run_ = new std::string(FreshDirectory("run"));
    learner_ = new Learner(StartLearner(absl::StrCat(
        "--env=InvertedPendulum --steps=100000000 --horizon=256 --envs=1 "
        "--segment_length=128 --max_live_actors=8 --actor_expiry_s=2 "
        "--max_unclaimed_per_peer=4 --claim_timeout_s=10 "
        "--idle_stream_timeout_s=2 --metrics=127.0.0.1:0 --auth_token_file=",
        *token_file_, " --run_dir=", *run_)));
    actor_pid_ = StartVantage(
        absl::StrCat("actor --learner=127.0.0.1:", learner_->port,
                     " --env=InvertedPendulum --envs=1 --auth_token_file=",
                     *token_file_),
        TempPath("actor.out"), TempPath("actor.err"));
    // Training under way before the first attack.
    WaitForNewVersions(3);
    baseline_rss_ = ProcessStatusField(learner_->pid, "VmRSS");
  }

  void TearDown() override {
    kill(actor_pid_, SIGTERM);
    WaitVantage(actor_pid_, 20);
    kill(learner_->pid, SIGTERM);
    EXPECT_EQ(WaitVantage(learner_->pid, 30), 0) << ReadFile(learner_->err);
    delete learner_;
    delete run_;
    delete token_file_;
  }

  // Versions the learner has recorded (rows of progress.csv).
  static int64_t Versions() {
    const int64_t rows = DeterministicProgress(*run_).size();
    return rows > 0 ? rows - 1 : 0;
  }

  // The real actor goes on training: `count` more versions within a
  // minute, and the learner's memory and threads within their bounds.
  static void WaitForNewVersions(int64_t count) {
    const int64_t before = Versions();
    for (int i = 0; i < 600 && Versions() < before + count; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    ASSERT_GE(Versions(), before + count) << "training stalled\n"
                                          << ReadFile(learner_->err);
  }

  void ExpectTrainingGoesOn() {
    WaitForNewVersions(3);
    const int64_t rss = ProcessStatusField(learner_->pid, "VmRSS");
    EXPECT_LT(rss, baseline_rss_ + kRssBoundBytes)
        << "learner RSS grew from " << baseline_rss_ << " to " << rss;
    // The server's threads stay bounded (a few per actor and call).
    EXPECT_LT(ProcessStatusField(learner_->pid, "Threads"), 80);
    for (const std::string& row : DeterministicProgress(*run_)) {
      EXPECT_THAT(row, ::testing::Not(HasSubstr("nan"))) << row;
    }
  }

  // Whether the learner's resident memory comes back to within `slack` of
  // `rss` within 30 s (it returns freed pages every 10 s).
  static bool ResidentMemoryReturnsTo(int64_t rss, int64_t slack) {
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (ProcessStatusField(learner_->pid, "VmRSS") > rss + slack) {
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    return true;
  }

  static std::shared_ptr<grpc::Channel> Channel() {
    grpc::ChannelArguments arguments;
    arguments.SetMaxSendMessageSize(-1);
    arguments.SetMaxReceiveMessageSize(-1);
    // A connection of its own per channel.
    arguments.SetInt("adversarial.channel", next_channel_++);
    return grpc::CreateCustomChannel(absl::StrCat("127.0.0.1:", learner_->port),
                                     grpc::InsecureChannelCredentials(),
                                     arguments);
  }

  static void Authorize(grpc::ClientContext& context, bool token = true) {
    context.set_deadline(std::chrono::system_clock::now() +
                         std::chrono::seconds(30));
    if (token) {
      context.AddMetadata("authorization", absl::StrCat("Bearer ", kToken));
    }
  }

  static grpc::Status Register(const pb::RegisterRequest& request,
                               Registered* registered = nullptr,
                               bool token = true) {
    auto stub = pb::Learner::NewStub(Channel());
    grpc::ClientContext context;
    Authorize(context, token);
    pb::RegisterResponse response;
    grpc::Status status = stub->Register(&context, request, &response);
    if (registered != nullptr && status.ok()) {
      registered->actor_id = response.actor_id();
      registered->session = response.session();
      registered->version = response.weights().version();
    }
    return status;
  }

  static Registered RegisterAttacker() {
    pb::RegisterRequest request;
    *request.mutable_spec() = PendulumSpecProto();
    request.set_num_envs(1);
    Registered registered;
    const grpc::Status status = Register(request, &registered);
    EXPECT_TRUE(status.ok()) << status.error_message();
    return registered;
  }

  // Streams `segments` with `session` and returns how the stream ended.
  static grpc::Status Stream(const std::string& session,
                             const std::vector<pb::Segment>& segments,
                             pb::SegmentAck* ack = nullptr) {
    auto stub = pb::Learner::NewStub(Channel());
    grpc::ClientContext context;
    Authorize(context);
    context.AddMetadata("vantage-session", session);
    pb::SegmentAck response;
    auto writer = stub->StreamSegments(&context, &response);
    for (const pb::Segment& segment : segments) {
      if (!writer->Write(segment)) break;
    }
    writer->WritesDone();
    const grpc::Status status = writer->Finish();
    if (ack != nullptr) *ack = response;
    return status;
  }

  static double Metric(const std::string& name) {
    absl::StatusOr<std::string> text =
        HttpGet(MetricsPort(learner_->err, "learner"), "/metrics");
    return text.ok() ? Sample(*text, name) : -1;
  }

  static std::string* token_file_;
  static std::string* run_;
  static Learner* learner_;
  static int actor_pid_;
  static int64_t baseline_rss_;
  static int next_channel_;
};

std::string* AdversarialTest::token_file_ = nullptr;
std::string* AdversarialTest::run_ = nullptr;
Learner* AdversarialTest::learner_ = nullptr;
int AdversarialTest::actor_pid_ = 0;
int64_t AdversarialTest::baseline_rss_ = 0;
int AdversarialTest::next_channel_ = 0;

TEST_F(AdversarialTest, PoisonedValuesAreRefusedByName) {
  const Registered attacker = RegisterAttacker();
  pb::Segment rewards = HonestSegment(attacker.actor_id, attacker.version, 0);
  *rewards.mutable_rewards() = FloatTensor({kSegmentSteps}, 3e38f);
  grpc::Status status = Stream(attacker.session, {rewards});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("rewards holds 3e+38"));
  pb::Segment log_probs = HonestSegment(attacker.actor_id, attacker.version, 0);
  *log_probs.mutable_behaviour_log_probs() =
      FloatTensor({kSegmentSteps}, -3e38f);
  status = Stream(attacker.session, {log_probs});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("behaviour_log_probs holds"));
  ExpectTrainingGoesOn();
  EXPECT_GE(
      Metric("vantage_learner_segments_rejected_total{reason=\"invalid\"}"), 2);
  EXPECT_EQ(Metric("vantage_learner_rolled_back_updates_total"), 0);
}

TEST_F(AdversarialTest, AnotherActorsIdOrSlotIsRefused) {
  const Registered attacker = RegisterAttacker();
  // The real actor registered first: it is actor 0.
  pb::Segment impersonating = HonestSegment(0, attacker.version, 1LL << 50);
  grpc::Status status = Stream(attacker.session, {impersonating});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_THAT(status.error_message(), HasSubstr("segment.actor_id 0"));
  pb::Segment slot = HonestSegment(attacker.actor_id, attacker.version, 0);
  slot.set_env_slot(113000);
  status = Stream(attacker.session, {slot});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_THAT(status.error_message(), HasSubstr("env_slot 113000"));
  // A made-up session, and another actor's id with a wrong secret.
  status = Stream("0:00000000000000000000000000000000", {impersonating});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  status = Stream("", {impersonating});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  ExpectTrainingGoesOn();
  EXPECT_GE(
      Metric(
          "vantage_learner_segments_rejected_total{reason=\"foreign_actor\"}"),
      1);
  EXPECT_GE(
      Metric("vantage_learner_segments_rejected_total{reason=\"bad_session\"}"),
      2);
}

TEST_F(AdversarialTest, TheSpecIsTheLearnersNotTheCallers) {
  pb::RegisterRequest request;
  request.set_num_envs(1);
  struct Case {
    std::function<void(pb::EnvSpec&)> change;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](pb::EnvSpec& s) { s.set_observation_size(1000000000); },
       "spec.observation_size: 1000000000, expected <= 65536"},
      {[](pb::EnvSpec& s) { s.set_observation_size(1000000); },
       "spec.observation_size: 1000000"},
      {[](pb::EnvSpec& s) {
         s.set_discrete(true);
         s.set_action_size(1000000000);
         s.clear_action_low();
         s.clear_action_high();
       },
       "spec.action_size: 1000000000"},
      {[](pb::EnvSpec& s) { s.set_max_episode_steps(1); },
       "differs in max_episode_steps: expected 1000, got 1"},
      {[](pb::EnvSpec& s) { s.set_observation_size(5); },
       "differs in observation_size"},
  };
  for (const Case& c : cases) {
    *request.mutable_spec() = PendulumSpecProto();
    c.change(*request.mutable_spec());
    const grpc::Status status = Register(request);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_THAT(status.error_message(), HasSubstr(c.message));
  }
  *request.mutable_spec() = PendulumSpecProto();
  request.set_num_envs(1000000);
  EXPECT_EQ(Register(request).error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  ExpectTrainingGoesOn();
}

TEST_F(AdversarialTest, BigMessagesBeforeAuthenticationCostNothing) {
  pb::RegisterRequest huge;
  *huge.mutable_spec() = PendulumSpecProto();
  huge.set_actor_name(std::string(200 << 20, 'x'));
  std::vector<std::future<grpc::Status>> calls;
  for (int i = 0; i < 8; ++i) {
    calls.push_back(std::async(std::launch::async, [&] {
      return Register(huge, nullptr, /*token=*/false);
    }));
  }
  for (auto& call : calls) {
    // Refused before its body is read; the transport may see the size
    // first.
    EXPECT_THAT(
        call.get().error_code(),
        AnyOf(grpc::StatusCode::UNAUTHENTICATED,
              grpc::StatusCode::RESOURCE_EXHAUSTED,
              grpc::StatusCode::UNAVAILABLE, grpc::StatusCode::CANCELLED));
  }
  // With the token, the learner still reads no more than its largest
  // segment, though gRPC holds the whole message before it refuses it; the
  // memory goes back to the system after.
  const int64_t rss_before = ProcessStatusField(learner_->pid, "VmRSS");
  const int64_t peak_before = ProcessStatusField(learner_->pid, "VmHWM");
  const grpc::Status status = Register(huge);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("larger than max"));
  EXPECT_LT(ProcessStatusField(learner_->pid, "VmHWM"),
            peak_before + kPeakPerMessageBytes);
  EXPECT_TRUE(ResidentMemoryReturnsTo(rss_before, 32 << 20))
      << "learner RSS " << ProcessStatusField(learner_->pid, "VmRSS")
      << " after the refusal, " << rss_before << " before";
  ExpectTrainingGoesOn();
}

TEST_F(AdversarialTest, EpisodeFloodsAndScalarTensorsAreRefused) {
  Registered attacker = RegisterAttacker();
  pb::Segment episodes = HonestSegment(attacker.actor_id, attacker.version, 0);
  for (int i = 0; i < 1000; ++i) {
    episodes.add_episode_returns(std::nan(""));
    episodes.add_episode_lengths(1);
  }
  grpc::Status status = Stream(attacker.session, {episodes});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("reports 1000 episodes"));
  // 12.6M episodes are more bytes than any segment of this run. Building
  // them outlasts a registration's 2 s expiry: the flood goes on a fresh one
  // (which has --claim_timeout_s to open its stream, on a busy machine too).
  pb::Segment flood = HonestSegment(attacker.actor_id, attacker.version, 0);
  flood.mutable_episode_lengths()->Resize(12600000, 1);
  flood.mutable_episode_returns()->Resize(12600000, 1.0);
  attacker = RegisterAttacker();
  flood.set_actor_id(attacker.actor_id);
  const int64_t peak_before = ProcessStatusField(learner_->pid, "VmHWM");
  status = Stream(attacker.session, {flood});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("larger than max"));
  EXPECT_LT(ProcessStatusField(learner_->pid, "VmHWM"),
            peak_before + kPeakPerMessageBytes);
  // Sending the flood can outlast the registration's 2 s expiry on a busy
  // machine: the next refusal is asked of a fresh registration.
  const Registered again = RegisterAttacker();
  pb::Segment scalar = HonestSegment(again.actor_id, again.version, 0);
  *scalar.mutable_rewards() = FloatTensor({}, 1.0f);
  status = Stream(again.session, {scalar});
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("0 steps"));
  ExpectTrainingGoesOn();
}

TEST_F(AdversarialTest, GarbageOnAStreamIsAnErrorAndCounted) {
  const Registered attacker = RegisterAttacker();
  grpc::GenericStub stub(Channel());
  grpc::ClientContext context;
  Authorize(context);
  context.AddMetadata("vantage-session", attacker.session);
  grpc::CompletionQueue queue;
  std::unique_ptr<grpc::GenericClientAsyncReaderWriter> call =
      stub.PrepareCall(&context, "/vantage.pb.Learner/StreamSegments", &queue);
  void* tag = nullptr;
  bool ok = false;
  call->StartCall(reinterpret_cast<void*>(1));
  ASSERT_TRUE(queue.Next(&tag, &ok) && ok);
  // A field tag with wire type 7, which no protobuf message can hold.
  const std::string bytes = "\x0f\xff\xff\xff garbage";
  grpc::Slice slice(bytes);
  grpc::ByteBuffer buffer(&slice, 1);
  call->Write(buffer, reinterpret_cast<void*>(2));
  ASSERT_TRUE(queue.Next(&tag, &ok));
  call->WritesDone(reinterpret_cast<void*>(3));
  ASSERT_TRUE(queue.Next(&tag, &ok));
  grpc::Status status;
  call->Finish(&status, reinterpret_cast<void*>(4));
  ASSERT_TRUE(queue.Next(&tag, &ok));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("is not a Segment"));
  queue.Shutdown();
  while (queue.Next(&tag, &ok)) {
  }
  ExpectTrainingGoesOn();
  EXPECT_GE(
      Metric("vantage_learner_segments_rejected_total{reason=\"unparsable\"}"),
      1);
}

TEST_F(AdversarialTest, RegistrationFloodsCannotLockActorsOut) {
  pb::RegisterRequest request;
  *request.mutable_spec() = PendulumSpecProto();
  request.set_num_envs(1);
  const double expired_before =
      Metric("vantage_learner_registration_expirations_total");
  // A loop of registrations that never open a call: this host may hold 4
  // such (--max_unclaimed_per_peer=4), whatever room the table has.
  int granted = 0;
  grpc::Status status;
  for (int i = 0; i < 20 && (status = Register(request)).ok(); ++i) ++granted;
  EXPECT_EQ(granted, 4);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(),
              HasSubstr("holds 4 registrations that have opened no call"));
  // They expire after --claim_timeout_s=10 (the real actor's, with its calls
  // open, does not), and then a new actor of this host registers. Polled
  // on the expirations counter for as long as a loaded machine may need.
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(40);
  while (Metric("vantage_learner_registration_expirations_total") <
             expired_before + granted &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  EXPECT_EQ(Metric("vantage_learner_registration_expirations_total"),
            expired_before + granted);
  EXPECT_EQ(Metric("vantage_learner_live_actors"), 1);
  EXPECT_TRUE(Register(request).ok());
  ExpectTrainingGoesOn();
}

TEST_F(AdversarialTest, ActorsThatLeftMakeRoomForNewOnes) {
  // Seven actors that streamed and left fill the table with the real one
  // (--max_live_actors=8) for --actor_expiry_s; a new actor is not refused
  // meanwhile: the one that left longest ago makes room.
  std::vector<Registered> left;
  for (int i = 0; i < 7; ++i) {
    left.push_back(RegisterAttacker());
    const grpc::Status streamed =
        Stream(left.back().session,
               {HonestSegment(left.back().actor_id, left.back().version, 0)});
    EXPECT_TRUE(streamed.ok()) << streamed.error_message();
  }
  pb::RegisterRequest request;
  *request.mutable_spec() = PendulumSpecProto();
  request.set_num_envs(1);
  Registered fresh;
  const grpc::Status status = Register(request, &fresh);
  EXPECT_TRUE(status.ok()) << status.error_message();
  // The evicted registration's session is over; the newest one's is not.
  EXPECT_EQ(Stream(left.front().session,
                   {HonestSegment(left.front().actor_id, fresh.version, 1)})
                .error_code(),
            grpc::StatusCode::NOT_FOUND);
  EXPECT_TRUE(
      Stream(fresh.session, {HonestSegment(fresh.actor_id, fresh.version, 0)})
          .ok());
  ExpectTrainingGoesOn();
}

TEST_F(AdversarialTest, IdleAndRepeatedStreamsHoldNoThreads) {
  const Registered attacker = RegisterAttacker();
  const int64_t threads_before = ProcessStatusField(learner_->pid, "Threads");
  // 200 streams of one session: each newer one ends the one before, so at
  // most one is open at a time.
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<std::unique_ptr<grpc::ClientWriter<pb::Segment>>> writers;
  std::vector<pb::SegmentAck> acks(200);
  auto stub = pb::Learner::NewStub(Channel());
  for (int i = 0; i < 200; ++i) {
    contexts.push_back(std::make_unique<grpc::ClientContext>());
    Authorize(*contexts.back());
    contexts.back()->AddMetadata("vantage-session", attacker.session);
    writers.push_back(stub->StreamSegments(contexts.back().get(), &acks[i]));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_LT(ProcessStatusField(learner_->pid, "Threads"), threads_before + 10);
  // The newest one, silent, is cancelled after --idle_stream_timeout_s=2.
  const grpc::Status last = writers.back()->Finish();
  EXPECT_EQ(last.error_code(), grpc::StatusCode::CANCELLED);
  for (int i = 0; i + 1 < 200; ++i) {
    EXPECT_EQ(writers[i]->Finish().error_code(), grpc::StatusCode::CANCELLED);
  }
  // The learner's series follow its gateway's counts at its next refresh:
  // polled, as a loaded machine may take a while.
  const std::string idle =
      "vantage_learner_segments_rejected_total{reason=\"idle_stream\"}";
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (Metric(idle) < 1 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  EXPECT_GE(Metric(idle), 1);
  ExpectTrainingGoesOn();
}

}  // namespace
}  // namespace vantage
