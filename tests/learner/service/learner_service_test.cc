#include "learner/service/learner_service.h"

#include <ATen/ATen.h>
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <future>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "common/env/environment.h"
#include "common/nn/networks.h"
#include "common/nn/policy_weights.h"
#include "common/nn/running_mean_std.h"
#include "common/rollout/segment.h"
#include "common/rollout/segment_queue.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/service/actor_gateway.h"
#include "proto/run_config.pb.h"
#include "proto/vantage.grpc.pb.h"
#include "proto/vantage.pb.h"
#include "proto/wire_format.h"
#include "tests/fakes/bit_equal.h"
#include "tests/fakes/pendulum_spec.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

constexpr int64_t kNoLimit = std::numeric_limits<int64_t>::max();
constexpr int64_t kObs = kPendulumObservationSize;
constexpr int64_t kAct = kPendulumActionSize;
// Guards every call so that a server that never answers fails the test
// instead of hanging it.
constexpr auto kRpcDeadline = std::chrono::seconds(30);

pb::RegisterRequest Request(const EnvSpec& spec) {
  pb::RegisterRequest request;
  EnvSpecToProto(spec, request.mutable_spec());
  request.set_actor_name("test-actor");
  request.set_num_envs(2);
  return request;
}

pb::RunConfig RunConfig() {
  pb::RunConfig config;
  config.mutable_training()->set_env("InvertedPendulum");
  config.mutable_ppo();
  config.mutable_training()->set_horizon(16);
  config.mutable_training()->set_segment_length(8);
  return config;
}

// Weights of a real policy and normaliser; every call draws new parameters,
// so two versions differ.
PolicyWeights MakeWeights(int64_t version) {
  NetworkConfig network;
  network.hidden = {8};
  PolicyNetwork policy(PendulumSpec(), network);
  RunningMeanStd normalizer(kObs);
  EXPECT_TRUE(normalizer
                  .Update(at::arange(3 * kObs, at::kFloat).reshape({3, kObs}) *
                          static_cast<double>(version + 1))
                  .ok());
  return ExportPolicyWeights(*policy, normalizer, version);
}

void ExpectWeightsAre(const pb::Weights& proto, const PolicyWeights& expected) {
  absl::StatusOr<PolicyWeights> got = WeightsFromProto(proto, kNoLimit);
  ASSERT_TRUE(got.ok()) << got.status();
  EXPECT_EQ(got->version, expected.version);
  ASSERT_EQ(got->parameters.size(), expected.parameters.size());
  for (size_t i = 0; i < expected.parameters.size(); ++i) {
    EXPECT_TRUE(BitEqual(got->parameters[i], expected.parameters[i]))
        << "parameter " << i;
  }
  EXPECT_EQ(got->normalizer_count, expected.normalizer_count);
  EXPECT_TRUE(BitEqual(got->normalizer_mean, expected.normalizer_mean));
  EXPECT_TRUE(BitEqual(got->normalizer_var, expected.normalizer_var));
}

// T steps whose values depend on `sequence`, with a truncation at step 1 and
// a termination at the last step, so final_observations is not empty.
Segment MakeSegment(int64_t actor_id, int64_t policy_version, int64_t sequence,
                    int64_t steps = 5, int64_t obs = kObs) {
  Segment segment;
  segment.actor_id = actor_id;
  segment.env_slot = 1;
  segment.sequence = sequence;
  segment.policy_version = policy_version;
  const double offset = 0.25 * static_cast<double>(sequence);
  segment.observations =
      at::arange((steps + 1) * obs, at::kFloat).reshape({steps + 1, obs}) *
          0.1 +
      offset;
  segment.actions =
      at::linspace(-2.5, 2.5, steps * kAct, at::kFloat).reshape({steps, kAct});
  segment.rewards = at::arange(steps, at::kFloat) * 0.5 - offset;
  segment.terminated = at::zeros({steps}, at::kBool);
  segment.truncated = at::zeros({steps}, at::kBool);
  segment.truncated[1] = true;
  segment.terminated[steps - 1] = true;
  segment.final_observations = at::full({1, obs}, 7.5f + offset, at::kFloat);
  segment.behaviour_log_probs = -at::arange(1, steps + 1, at::kFloat) * 0.01;
  segment.episode_returns = {2.5 + offset, -1.0};
  segment.episode_lengths = {2, 3};
  return segment;
}

pb::Segment ToProto(const Segment& segment) {
  pb::Segment proto;
  SegmentToProto(segment, &proto);
  return proto;
}

void ExpectSameSegment(const Segment& got, const Segment& expected) {
  EXPECT_EQ(got.actor_id, expected.actor_id);
  EXPECT_EQ(got.env_slot, expected.env_slot);
  EXPECT_EQ(got.sequence, expected.sequence);
  EXPECT_EQ(got.policy_version, expected.policy_version);
  EXPECT_TRUE(BitEqual(got.observations, expected.observations));
  EXPECT_TRUE(BitEqual(got.actions, expected.actions));
  EXPECT_TRUE(BitEqual(got.rewards, expected.rewards));
  EXPECT_TRUE(BitEqual(got.terminated, expected.terminated));
  EXPECT_TRUE(BitEqual(got.truncated, expected.truncated));
  EXPECT_TRUE(BitEqual(got.final_observations, expected.final_observations));
  EXPECT_TRUE(BitEqual(got.behaviour_log_probs, expected.behaviour_log_probs));
  EXPECT_EQ(got.episode_returns, expected.episode_returns);
  EXPECT_EQ(got.episode_lengths, expected.episode_lengths);
}

// Waits for a segment in `queue` without blocking forever when none comes.
absl::StatusOr<Segment> ReceiveWithin(SegmentQueue& queue,
                                      std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (queue.size() == 0) {
    if (std::chrono::steady_clock::now() > end) {
      return absl::DeadlineExceededError("no segment arrived");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return queue.Receive();
}

// A handler that was cancelled ends on its own thread after the client saw
// the cancellation, so counts it owns are read until they settle.
bool EventuallyEquals(const std::function<int64_t()>& read, int64_t expected,
                      std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (read() != expected) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

void SetDeadline(grpc::ClientContext& context) {
  context.set_deadline(std::chrono::system_clock::now() + kRpcDeadline);
}

struct StreamResult {
  grpc::Status status;
  pb::SegmentAck ack;
};

class LearnerServiceTest : public ::testing::Test {
 protected:
  ~LearnerServiceTest() override {
    // Waiters (subscriptions, registrations, blocked Sends) end first, so
    // that the server's shutdown does not wait for them.
    if (gateway_ != nullptr) gateway_->Close();
    if (queue_ != nullptr) queue_->Close();
    if (server_ != nullptr) {
      server_->Shutdown(std::chrono::system_clock::now() +
                        std::chrono::seconds(5));
    }
  }

  void Start(GatewayConfig config = DefaultConfig(), size_t capacity = 16) {
    queue_ = std::make_unique<SegmentQueue>(capacity);
    gateway_ = std::make_unique<ActorGateway>(std::move(config), *queue_);
    service_ = std::make_unique<LearnerService>(*gateway_);
    grpc::ServerBuilder builder;
    builder.RegisterService(service_.get());
    server_ = builder.BuildAndStart();
    ASSERT_NE(server_, nullptr);
    stub_ = pb::Learner::NewStub(
        server_->InProcessChannel(grpc::ChannelArguments()));
  }

  static GatewayConfig DefaultConfig() {
    GatewayConfig config;
    config.run_config = RunConfig();
    config.spec = PendulumSpec();
    config.max_segment_steps = 8;
    config.max_policy_lag = 0;
    return config;
  }

  grpc::Status Register(const EnvSpec& spec, pb::RegisterResponse* response) {
    grpc::ClientContext context;
    SetDeadline(context);
    return stub_->Register(&context, Request(spec), response);
  }

  // Registers actor 0 (its session in session_) and publishes version 0.
  void StartRegistered(GatewayConfig config = DefaultConfig(),
                       size_t capacity = 16) {
    Start(std::move(config), capacity);
    gateway_->Publish(MakeWeights(0));
    pb::RegisterResponse response;
    const grpc::Status status = Register(PendulumSpec(), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    ASSERT_EQ(response.actor_id(), 0);
    session_ = response.session();
  }

  // A stream that carries `session` (actor 0's by default).
  StreamResult Stream(const std::vector<pb::Segment>& segments) {
    return StreamWith(session_, segments);
  }
  StreamResult StreamWith(const std::string& session,
                          const std::vector<pb::Segment>& segments) {
    StreamResult result;
    grpc::ClientContext context;
    SetDeadline(context);
    context.AddMetadata(kSessionMetadataKey, session);
    std::unique_ptr<grpc::ClientWriter<pb::Segment>> writer =
        stub_->StreamSegments(&context, &result.ack);
    for (const pb::Segment& segment : segments) {
      // A refusal ends the stream early; later writes may then fail.
      if (!writer->Write(segment)) break;
    }
    writer->WritesDone();
    result.status = writer->Finish();
    return result;
  }

  // A refused segment ends its stream with `code` and a message holding
  // `message`, reaches no queue, is counted under `reason` only, and the
  // learner goes on serving new streams.
  void ExpectRefused(const pb::Segment& segment, grpc::StatusCode code,
                     const std::string& message, const std::string& reason) {
    const StreamResult refused = Stream({segment});
    EXPECT_EQ(refused.status.error_code(), code)
        << refused.status.error_message();
    EXPECT_THAT(refused.status.error_message(), HasSubstr(message));
    EXPECT_EQ(queue_->size(), 0u);
    const GatewayCounters counters = gateway_->counters();
    EXPECT_EQ(counters.rejected, (std::map<std::string, int64_t>{{reason, 1}}));
    EXPECT_EQ(counters.accepted_segments, 0);

    const Segment valid =
        MakeSegment(0, gateway_->published_version(), /*sequence=*/42);
    const StreamResult accepted = Stream({ToProto(valid)});
    ASSERT_TRUE(accepted.status.ok()) << accepted.status.error_message();
    EXPECT_EQ(accepted.ack.accepted(), 1);
    ASSERT_EQ(queue_->size(), 1u);
    absl::StatusOr<Segment> received = queue_->Receive();
    ASSERT_TRUE(received.ok()) << received.status();
    ExpectSameSegment(*received, valid);
    EXPECT_EQ(gateway_->counters().accepted_segments, 1);
  }

  std::unique_ptr<SegmentQueue> queue_;
  std::unique_ptr<ActorGateway> gateway_;
  std::unique_ptr<LearnerService> service_;
  std::unique_ptr<grpc::Server> server_;
  std::unique_ptr<pb::Learner::Stub> stub_;
  std::string session_;
};

// --- Register ---

TEST_F(LearnerServiceTest, RegisterMatchesThePinnedSpecAndNumbersActors) {
  Start();
  const PolicyWeights weights = MakeWeights(3);
  gateway_->Publish(weights);
  std::set<std::string> sessions;
  for (int64_t expected_id : {0, 1, 2}) {
    pb::RegisterResponse response;
    const grpc::Status status = Register(PendulumSpec(), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(response.actor_id(), expected_id);
    EXPECT_EQ(response.run_config().SerializeAsString(),
              RunConfig().SerializeAsString());
    ExpectWeightsAre(response.weights(), weights);
    // "<id>:" and 128 bits of hex, new for every registration.
    EXPECT_THAT(response.session(), ::testing::MatchesRegex(absl::StrCat(
                                        expected_id, ":[0-9a-f]{32}")));
    sessions.insert(response.session());
  }
  EXPECT_EQ(sessions.size(), 3u);
  const GatewayCounters counters = gateway_->counters();
  EXPECT_EQ(counters.registrations, 3);
  EXPECT_EQ(counters.live_actors, 3);
  EXPECT_EQ(counters.live_env_slots, 6);
}

TEST_F(LearnerServiceTest, RegisterWithAnotherSpecNamesTheField) {
  Start();
  gateway_->Publish(MakeWeights(0));
  pb::RegisterResponse response;
  ASSERT_TRUE(Register(PendulumSpec(), &response).ok());

  EnvSpec wider = PendulumSpec();
  wider.observation_size = 5;
  grpc::Status status = Register(wider, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("observation_size"));

  EnvSpec bounds = PendulumSpec();
  bounds.action_high = {2.0};
  status = Register(bounds, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("action_high"));

  // A spec no environment can have is refused before it is compared.
  EnvSpec broken = PendulumSpec();
  broken.action_low = {4.0};
  status = Register(broken, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);

  // Refusals take no actor id.
  pb::RegisterResponse second;
  status = Register(PendulumSpec(), &second);
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(second.actor_id(), 1);
  EXPECT_EQ(gateway_->counters().registrations, 2);
  EXPECT_EQ(gateway_->counters().refused_registrations, 3);
}

TEST_F(LearnerServiceTest, RegisterForAnotherEnvironmentIsRefused) {
  Start();
  gateway_->Publish(MakeWeights(0));
  EnvSpec hopper = PendulumSpec();
  hopper.name = "Hopper";
  pb::RegisterResponse response;
  const grpc::Status status = Register(hopper, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(),
              HasSubstr("this learner trains InvertedPendulum"));
  // The right environment still registers as actor 0.
  ASSERT_TRUE(Register(PendulumSpec(), &response).ok());
  EXPECT_EQ(response.actor_id(), 0);
}

TEST_F(LearnerServiceTest, RegisterWaitsForTheFirstWeights) {
  Start();
  const PolicyWeights weights = MakeWeights(5);
  std::thread publisher([&] {
    // Publish only once the registration is waiting.
    while (gateway_->counters().registrations == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    gateway_->Publish(weights);
  });
  pb::RegisterResponse response;
  const grpc::Status status = Register(PendulumSpec(), &response);
  publisher.join();
  ASSERT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(response.actor_id(), 0);
  ExpectWeightsAre(response.weights(), weights);
}

TEST_F(LearnerServiceTest, RegisterIsUnavailableWhenNoWeightsArrive) {
  Start();
  const auto begin = std::chrono::steady_clock::now();
  absl::StatusOr<pb::RegisterResponse> response = gateway_->Register(
      Request(PendulumSpec()), "test", absl::Milliseconds(100));
  const auto waited = std::chrono::steady_clock::now() - begin;
  EXPECT_TRUE(absl::IsUnavailable(response.status())) << response.status();
  EXPECT_GE(waited, std::chrono::milliseconds(90));
}

// --- StreamSegments ---

TEST_F(LearnerServiceTest, ValidSegmentsReachTheQueueUnchanged) {
  StartRegistered();
  const std::vector<Segment> segments = {MakeSegment(0, 0, 0, 5),
                                         MakeSegment(0, 0, 1, 8)};
  const StreamResult result =
      Stream({ToProto(segments[0]), ToProto(segments[1])});
  ASSERT_TRUE(result.status.ok()) << result.status.error_message();
  EXPECT_EQ(result.ack.accepted(), 2);
  EXPECT_EQ(result.ack.rejected(), 0);
  ASSERT_EQ(queue_->size(), 2u);
  for (const Segment& expected : segments) {
    absl::StatusOr<Segment> got = queue_->Receive();
    ASSERT_TRUE(got.ok()) << got.status();
    ExpectSameSegment(*got, expected);
  }
  const GatewayCounters counters = gateway_->counters();
  EXPECT_EQ(counters.accepted_segments, 2);
  EXPECT_EQ(counters.accepted_steps, 13);
  EXPECT_TRUE(counters.rejected.empty());
}

TEST_F(LearnerServiceTest, SegmentOfAnotherActorIsRefused) {
  StartRegistered();
  ExpectRefused(ToProto(MakeSegment(7, 0, 0)),
                grpc::StatusCode::PERMISSION_DENIED, "segment.actor_id 7",
                "foreign_actor");
}

TEST_F(LearnerServiceTest, SegmentOfAnUnpublishedVersionIsRefused) {
  StartRegistered();
  ExpectRefused(ToProto(MakeSegment(0, 1, 0)),
                grpc::StatusCode::FAILED_PRECONDITION, "segment.policy_version",
                "future_version");
}

TEST_F(LearnerServiceTest, TensorWithTheWrongByteCountIsRefused) {
  StartRegistered();
  pb::Segment segment = ToProto(MakeSegment(0, 0, 0));
  segment.mutable_rewards()->mutable_data()->resize(
      segment.rewards().data().size() - 4);
  ExpectRefused(segment, grpc::StatusCode::INVALID_ARGUMENT, "segment.rewards",
                "malformed");
}

TEST_F(LearnerServiceTest, NanRewardIsRefused) {
  StartRegistered();
  Segment segment = MakeSegment(0, 0, 0);
  segment.rewards[2] = std::nanf("");
  ExpectRefused(ToProto(segment), grpc::StatusCode::INVALID_ARGUMENT, "rewards",
                "invalid");
}

TEST_F(LearnerServiceTest, WrongObservationWidthIsRefused) {
  StartRegistered();
  ExpectRefused(ToProto(MakeSegment(0, 0, 0, 5, kObs + 1)),
                grpc::StatusCode::INVALID_ARGUMENT, "observations", "invalid");
}

TEST_F(LearnerServiceTest, TooManyStepsAreRefused) {
  StartRegistered();  // max_segment_steps = 8
  ExpectRefused(ToProto(MakeSegment(0, 0, 0, 9)),
                grpc::StatusCode::INVALID_ARGUMENT, "9 steps", "invalid");
}

TEST_F(LearnerServiceTest, StaleSegmentIsDroppedAndCounted) {
  StartRegistered();  // max_policy_lag = 0
  gateway_->Publish(MakeWeights(1));
  const StreamResult result = Stream({ToProto(MakeSegment(0, 0, 0))});
  ASSERT_TRUE(result.status.ok()) << result.status.error_message();
  EXPECT_EQ(result.ack.accepted(), 0);
  EXPECT_EQ(result.ack.rejected(), 1);
  EXPECT_THAT(result.ack.last_error(), HasSubstr("policy_version"));
  EXPECT_EQ(queue_->size(), 0u);
  EXPECT_EQ(gateway_->counters().rejected,
            (std::map<std::string, int64_t>{{"stale", 1}}));
  EXPECT_EQ(gateway_->counters().accepted_segments, 0);

  // The current version still gets through.
  const Segment current = MakeSegment(0, 1, 1);
  const StreamResult accepted = Stream({ToProto(current)});
  ASSERT_TRUE(accepted.status.ok()) << accepted.status.error_message();
  EXPECT_EQ(accepted.ack.accepted(), 1);
  absl::StatusOr<Segment> got = ReceiveWithin(*queue_, std::chrono::seconds(5));
  ASSERT_TRUE(got.ok()) << got.status();
  ExpectSameSegment(*got, current);
}

TEST_F(LearnerServiceTest, LaggingSegmentWithinTheAllowedLagIsAdmitted) {
  GatewayConfig config = DefaultConfig();
  config.max_policy_lag = 1;
  StartRegistered(config);
  gateway_->Publish(MakeWeights(1));
  gateway_->Publish(MakeWeights(2));
  const StreamResult result =
      Stream({ToProto(MakeSegment(0, 1, 0)), ToProto(MakeSegment(0, 0, 1)),
              ToProto(MakeSegment(0, 2, 2))});
  ASSERT_TRUE(result.status.ok()) << result.status.error_message();
  EXPECT_EQ(result.ack.accepted(), 2);
  EXPECT_EQ(result.ack.rejected(), 1);
  ASSERT_EQ(queue_->size(), 2u);
  EXPECT_EQ(queue_->Receive()->policy_version, 1);
  EXPECT_EQ(queue_->Receive()->policy_version, 2);
}

TEST_F(LearnerServiceTest, EveryRefusalIsCountedByItsReason) {
  StartRegistered();
  gateway_->Publish(MakeWeights(1));
  Segment nan = MakeSegment(0, 1, 0);
  nan.rewards[0] = std::nanf("");
  pb::Segment short_rewards = ToProto(MakeSegment(0, 1, 0));
  short_rewards.mutable_rewards()->mutable_data()->resize(3);
  const std::vector<pb::Segment> refused = {
      ToProto(MakeSegment(9, 1, 0)),
      ToProto(MakeSegment(0, 2, 0)),
      short_rewards,
      ToProto(nan),
      ToProto(MakeSegment(0, 1, 0, 5, kObs + 1)),
      ToProto(MakeSegment(0, 1, 0, 9)),
      ToProto(MakeSegment(0, 0, 0))};
  for (const pb::Segment& segment : refused) Stream({segment});
  EXPECT_EQ(queue_->size(), 0u);
  const GatewayCounters counters = gateway_->counters();
  EXPECT_EQ(counters.rejected, (std::map<std::string, int64_t>{
                                   {"foreign_actor", 1},
                                   {"future_version", 1},
                                   {"malformed", 1},
                                   {"invalid", 3},
                                   {"stale", 1},
                               }));
  EXPECT_EQ(counters.accepted_segments, 0);
}

// --- Sessions ---

TEST_F(LearnerServiceTest, SegmentOfASlotTheActorDidNotRegisterIsRefused) {
  StartRegistered();  // num_envs 2: slots 0 and 1
  Segment segment = MakeSegment(0, 0, 0);
  segment.env_slot = 2;
  ExpectRefused(ToProto(segment), grpc::StatusCode::PERMISSION_DENIED,
                "segment.env_slot 2", "foreign_slot");
}

TEST_F(LearnerServiceTest, StreamsWithoutTheRightSessionAreRefused) {
  StartRegistered();
  const pb::Segment segment = ToProto(MakeSegment(0, 0, 0));
  StreamResult result = StreamWith("", {segment});
  EXPECT_EQ(result.status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  std::string wrong = session_;
  wrong.back() = wrong.back() == '0' ? '1' : '0';
  result = StreamWith(wrong, {segment});
  EXPECT_EQ(result.status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_THAT(result.status.error_message(), HasSubstr("wrong session"));
  result = StreamWith("7:" + session_.substr(2), {segment});
  EXPECT_EQ(result.status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_EQ(queue_->size(), 0u);
  EXPECT_EQ(gateway_->counters().rejected,
            (std::map<std::string, int64_t>{{"bad_session", 2},
                                            {"unknown_session", 1}}));
}

TEST_F(LearnerServiceTest, AnAdmittedSequenceIsDroppedTheSecondTime) {
  StartRegistered();
  const pb::Segment segment = ToProto(MakeSegment(0, 0, 3));
  const StreamResult result = Stream({segment, segment});
  ASSERT_TRUE(result.status.ok()) << result.status.error_message();
  EXPECT_EQ(result.ack.accepted(), 1);
  EXPECT_EQ(result.ack.rejected(), 1);
  EXPECT_THAT(result.ack.last_error(), HasSubstr("already admitted"));
  EXPECT_EQ(queue_->size(), 1u);
  EXPECT_EQ(gateway_->counters().rejected,
            (std::map<std::string, int64_t>{{"duplicate", 1}}));
}

TEST_F(LearnerServiceTest, AnIdleRegistrationExpiresAndItsSessionEnds) {
  StartRegistered();
  // Not idle long enough yet.
  EXPECT_TRUE(gateway_->ExpireIdle(absl::Now()).empty());
  EXPECT_EQ(gateway_->ExpireIdle(absl::Now() + absl::Minutes(2)),
            std::vector<int64_t>{0});
  const GatewayCounters counters = gateway_->counters();
  EXPECT_EQ(counters.live_actors, 0);
  EXPECT_EQ(counters.live_env_slots, 0);
  EXPECT_EQ(counters.expirations, 1);
  const StreamResult result = Stream({ToProto(MakeSegment(0, 0, 0))});
  EXPECT_EQ(result.status.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(result.status.error_message(), HasSubstr("register again"));
}

TEST_F(LearnerServiceTest, RegistrationsStopAtTheLimits) {
  GatewayConfig config = DefaultConfig();
  config.limits.max_live_actors = 2;
  config.limits.max_live_env_slots = 3;
  Start(config);
  gateway_->Publish(MakeWeights(0));
  pb::RegisterResponse response;
  ASSERT_TRUE(Register(PendulumSpec(), &response).ok());  // 2 slots
  // A connected actor, which no registration can push out.
  ASSERT_TRUE(gateway_->Attach(response.session()).ok());
  grpc::Status status = Register(PendulumSpec(), &response);  // 4 > 3 slots
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("3 env slots"));
  pb::RegisterRequest one = Request(PendulumSpec());
  one.set_num_envs(1);
  grpc::ClientContext context;
  SetDeadline(context);
  ASSERT_TRUE(stub_->Register(&context, one, &response).ok());
  one.set_num_envs(0);
  grpc::ClientContext zero;
  SetDeadline(zero);
  status = stub_->Register(&zero, one, &response);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("num_envs is 0"));
  EXPECT_EQ(gateway_->counters().refused_registrations, 2);
}

// Registrations straight at the gateway, as from the host `peer`.
absl::StatusOr<pb::RegisterResponse> RegisterFrom(ActorGateway& gateway,
                                                  absl::string_view peer) {
  return gateway.Register(Request(PendulumSpec()), peer, absl::Seconds(5));
}

TEST_F(LearnerServiceTest, OneHostHoldsFewRegistrationsThatOpenedNoCall) {
  GatewayConfig config = DefaultConfig();
  config.limits.max_unclaimed_per_peer = 2;
  config.limits.claim_timeout = absl::Seconds(10);
  Start(config);
  gateway_->Publish(MakeWeights(0));
  const std::string host = "ipv4:10.0.0.1";
  absl::StatusOr<pb::RegisterResponse> first = RegisterFrom(*gateway_, host);
  ASSERT_TRUE(first.ok()) << first.status();
  ASSERT_TRUE(RegisterFrom(*gateway_, host).ok());
  absl::StatusOr<pb::RegisterResponse> third = RegisterFrom(*gateway_, host);
  EXPECT_TRUE(absl::IsResourceExhausted(third.status())) << third.status();
  EXPECT_THAT(third.status().message(),
              HasSubstr("ipv4:10.0.0.1 holds 2 registrations that have "
                        "opened no call (at most 2 per host)"));
  // Other hosts are not held up, and a registration that opens a call no
  // longer counts.
  EXPECT_TRUE(RegisterFrom(*gateway_, "ipv4:10.0.0.2").ok());
  absl::StatusOr<int64_t> attached = gateway_->Attach(first->session());
  ASSERT_TRUE(attached.ok()) << attached.status();
  EXPECT_TRUE(RegisterFrom(*gateway_, host).ok());
  EXPECT_EQ(gateway_->counters().refused_registrations, 1);
  // Unclaimed ones expire after claim_timeout, long before actor_expiry;
  // the claimed one, with its call open, stays.
  EXPECT_TRUE(gateway_->ExpireIdle(absl::Now()).empty());
  EXPECT_THAT(gateway_->ExpireIdle(absl::Now() + absl::Seconds(11)),
              ::testing::UnorderedElementsAre(1, 2, 3));
  EXPECT_EQ(gateway_->counters().live_actors, 1);
}

TEST_F(LearnerServiceTest, AFullTableMakesRoomFromTheLongestIdle) {
  GatewayConfig config = DefaultConfig();
  config.limits.max_live_actors = 3;
  config.limits.max_live_env_slots = 8;
  Start(config);
  gateway_->Publish(MakeWeights(0));
  absl::StatusOr<pb::RegisterResponse> connected = RegisterFrom(*gateway_, "a");
  ASSERT_TRUE(connected.ok()) << connected.status();
  ASSERT_TRUE(gateway_->Attach(connected->session()).ok());
  absl::StatusOr<pb::RegisterResponse> left = RegisterFrom(*gateway_, "b");
  ASSERT_TRUE(left.ok()) << left.status();
  ASSERT_TRUE(gateway_->Attach(left->session()).ok());
  gateway_->Detach(left->actor_id());  // an actor that went away
  absl::StatusOr<pb::RegisterResponse> silent = RegisterFrom(*gateway_, "c");
  ASSERT_TRUE(silent.ok()) << silent.status();
  // The table is full: the actor that left longest ago makes room, then
  // the silent registration; the connected actor never does.
  absl::StatusOr<pb::RegisterResponse> restarted = RegisterFrom(*gateway_, "b");
  ASSERT_TRUE(restarted.ok()) << restarted.status();
  EXPECT_TRUE(absl::IsNotFound(gateway_->Attach(left->session()).status()));
  ASSERT_TRUE(gateway_->Attach(restarted->session()).ok());
  absl::StatusOr<pb::RegisterResponse> fourth = RegisterFrom(*gateway_, "d");
  ASSERT_TRUE(fourth.ok()) << fourth.status();
  EXPECT_TRUE(absl::IsNotFound(gateway_->Attach(silent->session()).status()));
  // The evicted are handed to the learner to free, once.
  EXPECT_THAT(gateway_->ExpireIdle(absl::Now()),
              ::testing::ElementsAre(left->actor_id(), silent->actor_id()));
  EXPECT_TRUE(gateway_->ExpireIdle(absl::Now()).empty());
  EXPECT_EQ(gateway_->counters().expirations, 2);
  // A registration that would not fit even with every idle one gone
  // evicts none of them.
  pb::RegisterRequest too_many = Request(PendulumSpec());
  too_many.set_num_envs(5);  // 6 live slots, 2 of them idle: 9 > 8
  EXPECT_TRUE(absl::IsResourceExhausted(
      gateway_->Register(too_many, "e", absl::Seconds(5)).status()));
  EXPECT_TRUE(gateway_->ExpireIdle(absl::Now()).empty());
  EXPECT_EQ(gateway_->counters().live_actors, 3);
  // With every registration connected, there is no room to make.
  ASSERT_TRUE(gateway_->Attach(fourth->session()).ok());
  absl::StatusOr<pb::RegisterResponse> refused = RegisterFrom(*gateway_, "e");
  EXPECT_TRUE(absl::IsResourceExhausted(refused.status())) << refused.status();
  EXPECT_THAT(refused.status().message(),
              HasSubstr("every registration has a call open"));
}

TEST_F(LearnerServiceTest, ANewerStreamOfTheSameActorEndsTheOlder) {
  StartRegistered();
  grpc::ClientContext first;
  SetDeadline(first);
  first.AddMetadata(kSessionMetadataKey, session_);
  pb::SegmentAck ack;
  auto older = stub_->StreamSegments(&first, &ack);
  ASSERT_TRUE(older->Write(ToProto(MakeSegment(0, 0, 0))));
  ASSERT_TRUE(ReceiveWithin(*queue_, std::chrono::seconds(5)).ok());
  const StreamResult newer = Stream({ToProto(MakeSegment(0, 0, 1))});
  EXPECT_TRUE(newer.status.ok()) << newer.status.error_message();
  EXPECT_EQ(older->Finish().error_code(), grpc::StatusCode::CANCELLED);
  EXPECT_TRUE(EventuallyEquals([&] { return service_->open_streams(); }, 0,
                               std::chrono::seconds(5)))
      << service_->open_streams() << " streams still open";
}

// --- Weights ---

TEST_F(LearnerServiceTest, GetWeightsIsUnavailableUntilPublished) {
  Start();
  pb::Weights weights;
  {
    grpc::ClientContext context;
    SetDeadline(context);
    const grpc::Status status =
        stub_->GetWeights(&context, pb::WeightsRequest(), &weights);
    EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAVAILABLE);
  }
  const PolicyWeights published = MakeWeights(4);
  gateway_->Publish(published);
  grpc::ClientContext context;
  SetDeadline(context);
  const grpc::Status status =
      stub_->GetWeights(&context, pb::WeightsRequest(), &weights);
  ASSERT_TRUE(status.ok()) << status.error_message();
  ExpectWeightsAre(weights, published);
}

TEST_F(LearnerServiceTest,
       SubscriptionDeliversTheWeightsInForceThenEachNewerVersion) {
  StartRegistered();  // publishes version 0
  grpc::ClientContext context;
  SetDeadline(context);
  context.AddMetadata(kSessionMetadataKey, session_);
  pb::WeightsRequest request;
  request.set_actor_id(0);
  request.set_known_version(0);
  std::unique_ptr<grpc::ClientReader<pb::Weights>> reader =
      stub_->SubscribeWeights(&context, request);
  // First the weights in force, whatever version the actor knows: their
  // grant of horizons may be newer than its registration's.
  pb::Weights in_force;
  ASSERT_TRUE(reader->Read(&in_force));
  EXPECT_EQ(in_force.version(), 0);
  EXPECT_TRUE(in_force.has_horizons());

  for (int64_t version : {1, 2}) {
    const PolicyWeights published = MakeWeights(version);
    gateway_->Publish(published);
    pb::Weights weights;
    ASSERT_TRUE(reader->Read(&weights));
    ExpectWeightsAre(weights, published);
  }
  context.TryCancel();
  pb::Weights extra;
  EXPECT_FALSE(reader->Read(&extra));
  EXPECT_EQ(reader->Finish().error_code(), grpc::StatusCode::CANCELLED);

  // The server's side ends too, with the gateway still open: shutdown
  // waits for running handlers.
  std::future<void> shutdown = std::async(std::launch::async, [&] {
    server_->Shutdown(std::chrono::system_clock::now() +
                      std::chrono::seconds(10));
  });
  const bool ended =
      shutdown.wait_for(std::chrono::seconds(3)) == std::future_status::ready;
  EXPECT_TRUE(ended) << "the subscription outlived its cancellation";
  // Closing the gateway is what ends a handler that ignored it.
  if (!ended) gateway_->Close();
}

TEST_F(LearnerServiceTest, SubscriptionEndsWhenTheGatewayCloses) {
  StartRegistered();
  const PolicyWeights published = MakeWeights(1);
  gateway_->Publish(published);
  grpc::ClientContext context;
  SetDeadline(context);
  context.AddMetadata(kSessionMetadataKey, session_);
  pb::WeightsRequest request;
  request.set_known_version(-1);
  std::unique_ptr<grpc::ClientReader<pb::Weights>> reader =
      stub_->SubscribeWeights(&context, request);
  pb::Weights weights;
  ASSERT_TRUE(reader->Read(&weights));
  ExpectWeightsAre(weights, published);

  gateway_->Close();
  EXPECT_FALSE(reader->Read(&weights));
  const grpc::Status status = reader->Finish();
  EXPECT_TRUE(status.ok()) << status.error_message();
}

// --- Backpressure ---

TEST_F(LearnerServiceTest, FullQueueBlocksTheStreamUntilDrained) {
  StartRegistered(DefaultConfig(), /*capacity=*/1);
  const std::vector<Segment> segments = {
      MakeSegment(0, 0, 0), MakeSegment(0, 0, 1), MakeSegment(0, 0, 2)};
  std::future<StreamResult> stream = std::async(std::launch::async, [&] {
    return Stream(
        {ToProto(segments[0]), ToProto(segments[1]), ToProto(segments[2])});
  });
  EXPECT_EQ(stream.wait_for(std::chrono::milliseconds(300)),
            std::future_status::timeout);
  EXPECT_EQ(queue_->size(), 1u);
  for (const Segment& expected : segments) {
    absl::StatusOr<Segment> got =
        ReceiveWithin(*queue_, std::chrono::seconds(10));
    ASSERT_TRUE(got.ok()) << got.status();
    ExpectSameSegment(*got, expected);
  }
  ASSERT_EQ(stream.wait_for(std::chrono::seconds(10)),
            std::future_status::ready);
  const StreamResult result = stream.get();
  ASSERT_TRUE(result.status.ok()) << result.status.error_message();
  EXPECT_EQ(result.ack.accepted(), 3);
}

}  // namespace

TEST(PeerHostTest, DropsThePortOfNetworkPeersOnly) {
  EXPECT_EQ(PeerHost("ipv4:10.0.0.7:41234"), "ipv4:10.0.0.7");
  EXPECT_EQ(PeerHost("ipv6:[::1]:41234"), "ipv6:[::1]");
  EXPECT_EQ(PeerHost("ipv6:%5B::1%5D:5"), "ipv6:%5B::1%5D");
  EXPECT_EQ(PeerHost("unix:/tmp/learner.sock"), "unix:/tmp/learner.sock");
  EXPECT_EQ(PeerHost("inproc"), "inproc");
}

}  // namespace vantage
