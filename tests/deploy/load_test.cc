// A learner under idle load: 1,000 streams and 50 registered actors that
// never send anything, while a real actor trains. Its training throughput
// must stay within 20% of the undisturbed rate measured in the same test,
// and the learner's threads and memory must stay bounded.

#include <grpcpp/grpcpp.h>
#include <signal.h>

#include <chrono>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "gtest/gtest.h"
#include "proto/vantage.grpc.pb.h"
#include "proto/vantage.pb.h"
#include "tests/deploy/cli/run_vantage.h"
#include "tests/fakes/learner_process.h"
#include "tests/fakes/pendulum_spec.h"
#include "tests/fakes/run_files.h"

namespace vantage {
namespace {

constexpr int kIdleStreams = 1000;
constexpr int kSilentActors = 50;
constexpr int kChannels = 100;  // 10 streams each, within HTTP/2's limits

int64_t Versions(const std::string& run) {
  const int64_t rows = DeterministicProgress(run).size();
  return rows > 0 ? rows - 1 : 0;
}

// Policy versions per second over `versions` new versions (the best of
// three windows: interference only slows a window down).
double VersionsPerSecond(const std::string& run, int64_t versions) {
  double best = 0.0;
  for (int window = 0; window < 3; ++window) {
    const int64_t start = Versions(run);
    const auto begin = std::chrono::steady_clock::now();
    while (Versions(run) < start + versions &&
           std::chrono::steady_clock::now() - begin < std::chrono::minutes(2)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - begin)
            .count();
    best = std::max(best, (Versions(run) - start) / seconds);
  }
  return best;
}

TEST(LoadTest, IdleStreamsAndSilentActorsDoNotSlowTraining) {
  const std::string run = FreshDirectory("load");
  const Learner learner = StartLearner(
      "--env=InvertedPendulum --steps=100000000 --horizon=512 --envs=1 "
      "--segment_length=128 --max_live_actors=64 --run_dir=" +
      run);
  const int actor = StartVantage("actor --learner=127.0.0.1:" + learner.port +
                                     " --env=InvertedPendulum --envs=1",
                                 TempPath("actor.out"), TempPath("actor.err"));
  while (Versions(run) < 3) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const double undisturbed = VersionsPerSecond(run, 15);
  const int64_t threads_before = ProcessStatusField(learner.pid, "Threads");
  const int64_t rss_before = ProcessStatusField(learner.pid, "VmRSS");

  std::vector<std::shared_ptr<grpc::Channel>> channels;
  for (int i = 0; i < kChannels; ++i) {
    grpc::ChannelArguments arguments;
    arguments.SetInt("load.channel", i);  // a connection each
    channels.push_back(grpc::CreateCustomChannel(
        "127.0.0.1:" + learner.port, grpc::InsecureChannelCredentials(),
        arguments));
  }
  std::vector<std::string> sessions;
  for (int i = 0; i < kSilentActors; ++i) {
    auto stub = pb::Learner::NewStub(channels[i % kChannels]);
    pb::RegisterRequest request;
    *request.mutable_spec() = PendulumSpecProto();
    request.set_num_envs(1);
    grpc::ClientContext context;
    pb::RegisterResponse response;
    const grpc::Status status = stub->Register(&context, request, &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    sessions.push_back(response.session());
  }
  // Streams that never send: half carry a silent actor's session (each
  // newer one ends that actor's older one), half none (refused at once).
  std::vector<std::unique_ptr<grpc::ClientContext>> contexts;
  std::vector<std::unique_ptr<grpc::ClientWriter<pb::Segment>>> writers;
  std::vector<pb::SegmentAck> acks(kIdleStreams);
  std::vector<std::unique_ptr<pb::Learner::Stub>> stubs;
  for (const auto& channel : channels) {
    stubs.push_back(pb::Learner::NewStub(channel));
  }
  for (int i = 0; i < kIdleStreams; ++i) {
    contexts.push_back(std::make_unique<grpc::ClientContext>());
    if (i % 2 == 0) {
      contexts.back()->AddMetadata("vantage-session",
                                   sessions[(i / 2) % kSilentActors]);
    }
    writers.push_back(
        stubs[i % kChannels]->StreamSegments(contexts.back().get(), &acks[i]));
  }
  // Let the server take in the new connections before the clock starts.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const double loaded = VersionsPerSecond(run, 15);
  const int64_t threads_loaded = ProcessStatusField(learner.pid, "Threads");
  const int64_t rss_loaded = ProcessStatusField(learner.pid, "VmRSS");
  // At most one open stream per silent actor holds a server thread.
  EXPECT_LT(threads_loaded, threads_before + kSilentActors + 20);
  EXPECT_LT(rss_loaded, rss_before + (200 << 20));

  for (auto& context : contexts) context->TryCancel();
  for (auto& writer : writers) writer->Finish();
  // Undisturbed again after the load (A-B-A): a machine that slowed down
  // or sped up during the test moves both baselines, not the comparison.
  std::this_thread::sleep_for(std::chrono::seconds(2));
  const double undisturbed_after = VersionsPerSecond(run, 15);
  const double baseline = (undisturbed + undisturbed_after) / 2;
  std::printf(
      "load: %.2f versions/s undisturbed (%.2f before, %.2f after), %.2f "
      "under %d idle streams and %d silent actors; learner threads %ld -> "
      "%ld, RSS %ld -> %ld MB\n",
      baseline, undisturbed, undisturbed_after, loaded, kIdleStreams,
      kSilentActors, static_cast<long>(threads_before),
      static_cast<long>(threads_loaded), static_cast<long>(rss_before >> 20),
      static_cast<long>(rss_loaded >> 20));
  EXPECT_GE(loaded, 0.8 * baseline);
  kill(actor, SIGTERM);
  EXPECT_EQ(WaitVantage(actor, 20), 0);
  kill(learner.pid, SIGTERM);
  EXPECT_EQ(WaitVantage(learner.pid, 30), 0) << ReadFile(learner.err);
}

}  // namespace
}  // namespace vantage
