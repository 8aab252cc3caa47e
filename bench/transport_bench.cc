#include "bench/transport_bench.h"

#include <benchmark/benchmark.h>
#include <grpcpp/grpcpp.h>
#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "actor/actor_core.h"
#include "actor/envs/env_registry.h"
#include "actor/remote/remote_actor.h"
#include "bench/consuming_learner.h"
#include "bench/fastest.h"
#include "bench/raw_physics.h"
#include "common/net/port_file.h"
#include "common/nn/compute_threads.h"
#include "common/nn/networks.h"
#include "common/util/self_process.h"
#include "proto/vantage.grpc.pb.h"
#include "proto/wire_format.h"

namespace vantage {
namespace {

constexpr char kEnv[] = "HalfCheetah";
constexpr int kActorEnvs = 16;
constexpr int64_t kSegmentLength = 128;
// Each timed measurement is split into this many windows and the fastest
// kept: on a shared machine interference only ever slows a window down.
constexpr int kWindows = 5;

double Now() {
  return std::chrono::duration<double>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int Fail(const char* bench, const absl::Status& status) {
  std::fprintf(stderr, "vantage bench %s: %s\n", bench,
               std::string(status.message()).c_str());
  return 1;
}

pb::RunConfig BenchRunConfig(const std::string& env,
                             const NetworkConfig& network = NetworkConfig()) {
  pb::RunConfig run;
  pb::TrainingSettings& training = *run.mutable_training();
  training.set_env(env);
  training.set_horizon(2048);
  training.set_segment_length(kSegmentLength);
  training.add_hidden(64);
  training.add_hidden(64);
  if (network.recurrent()) {
    training.set_core(CoreName(network.core));
    training.set_core_size(network.core_size);
    training.set_seq_len(kSegmentLength);
  }
  run.mutable_distributed()->set_sync(false);
  run.mutable_distributed()->set_max_policy_lag(4);
  return run;
}

// Version 0 of a fresh 64x64 policy for `spec` (with `core`'s recurrent
// core, if any).
PolicyWeights FreshWeights(const EnvSpec& spec,
                           const NetworkConfig& core = NetworkConfig()) {
  NetworkConfig network = core;
  network.hidden = {64, 64};
  PolicyNetwork policy(spec, network);
  RunningMeanStd normalizer(spec.observation_size);
  return ExportPolicyWeights(*policy, normalizer, 0);
}

// Counts what an actor core produces and keeps the first segments.
class CountingSink : public SegmentSink {
 public:
  absl::Status Send(Segment segment) override {
    steps_ += segment.steps();
    if (kept_.size() < kActorEnvs) kept_.push_back(std::move(segment));
    return absl::OkStatus();
  }
  int64_t steps() const { return steps_; }
  const std::vector<Segment>& kept() const { return kept_; }

 private:
  int64_t steps_ = 0;
  std::vector<Segment> kept_;
};

struct ActorRate {
  double steps_per_second = 0.0;
  std::vector<Segment> segments;  // one round of real segments
};

// One actor on one thread with no transport: 16 HalfCheetah envs, batched
// inference, segments built.
absl::StatusOr<ActorRate> MeasureActorCore(const PolicyWeights& weights,
                                           double seconds) {
  ActorConfig config;
  config.env = kEnv;
  config.num_envs = kActorEnvs;
  config.segment_length = kSegmentLength;
  config.network.hidden = {64, 64};
  absl::StatusOr<std::unique_ptr<ActorCore>> actor = ActorCore::Create(config);
  if (!actor.ok()) return actor.status();
  if (absl::Status status = (*actor)->SetWeights(weights); !status.ok()) {
    return status;
  }
  CountingSink sink;
  // A warm-up round, then the timed ones.
  if (absl::Status status = (*actor)->CollectSegments(sink); !status.ok()) {
    return status;
  }
  double fastest = 0.0;
  for (int window = 0; window < kWindows; ++window) {
    const int64_t before = sink.steps();
    const double start = Now();
    while (Now() - start < seconds / kWindows) {
      if (absl::Status status = (*actor)->CollectSegments(sink); !status.ok()) {
        return status;
      }
    }
    fastest = std::max(fastest, (sink.steps() - before) / (Now() - start));
  }
  ActorRate rate;
  rate.steps_per_second = fastest;
  rate.segments = sink.kept();
  return rate;
}

// The learner's steps stitched per second over `seconds` split into
// kWindows windows, the fastest kept.
double FastestIngestRate(const ConsumingLearner& learner, double seconds) {
  double fastest = 0.0;
  for (int window = 0; window < kWindows; ++window) {
    const int64_t before = learner.consumed_steps();
    const double start = Now();
    std::this_thread::sleep_for(
        std::chrono::duration<double>(seconds / kWindows));
    fastest = std::max(fastest,
                       (learner.consumed_steps() - before) / (Now() - start));
  }
  return fastest;
}

// One client: registers, then streams copies of `segments` (renumbered as
// its own consecutive streams) until `stop`, or only `rounds` of them
// (rounds >= 0) and then holds its stream open, idle, until `stop`.
absl::Status StreamCopies(int port, int client, const EnvSpec& spec,
                          const std::vector<pb::Segment>& segments,
                          const std::atomic<bool>& stop, int rounds = -1,
                          std::atomic<int>* streaming = nullptr) {
  grpc::ChannelArguments arguments;
  // A connection of its own, as separate actor processes would have.
  arguments.SetInt("vantage.bench_client", client);
  arguments.SetMaxSendMessageSize(256 << 20);
  const std::shared_ptr<grpc::Channel> channel =
      grpc::CreateCustomChannel(absl::StrCat("127.0.0.1:", port),
                                grpc::InsecureChannelCredentials(), arguments);
  std::unique_ptr<pb::Learner::Stub> stub = pb::Learner::NewStub(channel);
  pb::RegisterRequest request;
  EnvSpecToProto(spec, request.mutable_spec());
  request.set_actor_name(absl::StrCat("bench-", client));
  request.set_num_envs(static_cast<int>(segments.size()));
  pb::RegisterResponse response;
  grpc::ClientContext register_context;
  if (grpc::Status status =
          stub->Register(&register_context, request, &response);
      !status.ok()) {
    return absl::UnavailableError(status.error_message());
  }
  std::vector<pb::Segment> copies = segments;
  for (pb::Segment& copy : copies) copy.set_actor_id(response.actor_id());
  grpc::ClientContext stream_context;
  stream_context.AddMetadata(kSessionMetadataKey, response.session());
  pb::SegmentAck ack;
  std::unique_ptr<grpc::ClientWriter<pb::Segment>> writer =
      stub->StreamSegments(&stream_context, &ack);
  for (int64_t sequence = 0; !stop && (rounds < 0 || sequence < rounds);
       ++sequence) {
    for (pb::Segment& copy : copies) {
      copy.set_sequence(sequence);
      if (!writer->Write(copy)) break;
    }
  }
  if (streaming != nullptr) ++*streaming;
  while (!stop) std::this_thread::sleep_for(std::chrono::milliseconds(50));
  writer->WritesDone();
  const grpc::Status finished = writer->Finish();
  if (!finished.ok() && !stop) {
    return absl::UnavailableError(finished.error_message());
  }
  return absl::OkStatus();
}

}  // namespace

int RunIngestBenchmark(int clients, double seconds) {
  SetComputeThreads(1);
  absl::StatusOr<std::unique_ptr<Environment>> probe = MakeEnvironment(kEnv);
  if (!probe.ok()) return Fail("ingest", probe.status());
  const EnvSpec spec = (*probe)->spec();
  const PolicyWeights weights = FreshWeights(spec);
  absl::StatusOr<ActorRate> actor = MeasureActorCore(weights, seconds);
  if (!actor.ok()) return Fail("ingest", actor.status());
  std::vector<pb::Segment> segments(actor->segments.size());
  for (size_t i = 0; i < segments.size(); ++i) {
    SegmentToProto(actor->segments[i], &segments[i]);
  }

  absl::StatusOr<std::unique_ptr<ConsumingLearner>> learner =
      ConsumingLearner::Start(BenchRunConfig(kEnv), spec, weights,
                              /*steps_per_version=*/0);
  if (!learner.ok()) return Fail("ingest", learner.status());
  std::atomic<bool> stop{false};
  std::vector<absl::Status> results(clients);
  std::vector<std::thread> threads;
  for (int i = 0; i < clients; ++i) {
    threads.emplace_back([&, i] {
      results[i] = StreamCopies((*learner)->port(), i, spec, segments, stop);
    });
  }
  // A second to connect and fill the pipes, then the window.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double ingested = FastestIngestRate(**learner, seconds);
  stop = true;
  learner->reset();  // ends the streams
  for (std::thread& thread : threads) thread.join();
  for (const absl::Status& result : results) {
    if (!result.ok()) return Fail("ingest", result);
  }
  std::printf(
      "ingest: %d loopback clients streaming %ld-step %s segments into a "
      "learner that validates and stitches them; one actor (%d envs, "
      "batched inference, one thread) makes %.0f steps/s\n",
      clients, static_cast<long>(kSegmentLength), kEnv, kActorEnvs,
      actor->steps_per_second);
  std::printf(
      "RESULT ingest clients=%d steps_per_s=%.0f actor_steps_per_s=%.0f "
      "actors_fed=%.1f\n",
      clients, ingested, actor->steps_per_second,
      ingested / actor->steps_per_second);
  return 0;
}

namespace {

// A process's resident set and thread count, from /proc.
struct ProcessFootprint {
  double rss_mb = 0.0;
  int threads = 0;
};

ProcessFootprint FootprintOf(pid_t pid) {
  ProcessFootprint footprint;
  std::ifstream status(absl::StrCat("/proc/", pid, "/status"));
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      double kb = 0;
      status >> kb;
      footprint.rss_mb = kb / 1024;
    } else if (key == "Threads:") {
      status >> footprint.threads;
    }
  }
  return footprint;
}

// Waits for `path` to hold a port; 0 if `pid` ends first or 60 s pass.
int WaitForPortFile(pid_t pid, const std::string& path) {
  for (int i = 0; i < 3000; ++i) {
    if (const std::optional<int> port = ReadPortFile(path)) return *port;
    if (waitpid(pid, nullptr, WNOHANG) == pid) return 0;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return 0;
}

}  // namespace

int RunConnectionsBenchmark(int max_actors) {
  constexpr char kTinyEnv[] = "InvertedPendulum";
  absl::StatusOr<std::unique_ptr<Environment>> probe =
      MakeEnvironment(kTinyEnv);
  if (!probe.ok()) return Fail("connections", probe.status());
  const EnvSpec spec = (*probe)->spec();
  // One real 128-step segment of one env, which every client sends once.
  ActorConfig actor_config;
  actor_config.env = kTinyEnv;
  actor_config.num_envs = 1;
  actor_config.segment_length = kSegmentLength;
  actor_config.network.hidden = {64, 64};
  absl::StatusOr<std::unique_ptr<ActorCore>> actor =
      ActorCore::Create(actor_config);
  if (!actor.ok()) return Fail("connections", actor.status());
  CountingSink sink;
  if (absl::Status status = (*actor)->SetWeights(FreshWeights(spec));
      !status.ok()) {
    return Fail("connections", status);
  }
  if (absl::Status status = (*actor)->CollectSegments(sink); !status.ok()) {
    return Fail("connections", status);
  }
  std::vector<pb::Segment> segment(1);
  SegmentToProto(sink.kept().at(0), &segment[0]);

  // A real learner process whose batch (one rollout per actor) never
  // completes, so that what it holds is the actors' state alone.
  const std::string port_file =
      absl::StrCat(std::filesystem::temp_directory_path().string(),
                   "/vantage-bench-connections-", ::getpid(), ".port");
  std::error_code error;
  std::filesystem::remove(port_file, error);
  absl::StatusOr<pid_t> learner =
      SpawnSelf({"learner", absl::StrCat("--env=", kTinyEnv),
                 absl::StrCat("--actors=", max_actors), "--envs_per_actor=1",
                 "--nosync", absl::StrCat("--segment_length=", kSegmentLength),
                 "--listen=127.0.0.1:0", "--port_file=" + port_file,
                 absl::StrCat("--max_live_actors=", max_actors),
                 absl::StrCat("--max_server_threads=", 2 * max_actors + 64)},
                port_file + ".log");
  if (!learner.ok()) return Fail("connections", learner.status());
  const int port = WaitForPortFile(*learner, port_file);
  if (port == 0) {
    kill(*learner, SIGKILL);
    waitpid(*learner, nullptr, 0);
    return Fail("connections",
                absl::InternalError(absl::StrCat("the learner did not start (",
                                                 port_file, ".log)")));
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const ProcessFootprint idle = FootprintOf(*learner);
  std::printf("connections: learner idle: %.1f MB, %d threads\n", idle.rss_mb,
              idle.threads);
  std::atomic<bool> stop{false};
  std::atomic<int> streaming{0};
  std::vector<absl::Status> results(max_actors);
  std::vector<std::thread> clients;
  ProcessFootprint last = idle;
  for (int level :
       {max_actors / 4, max_actors / 2, 3 * max_actors / 4, max_actors}) {
    while (static_cast<int>(clients.size()) < level) {
      const int i = static_cast<int>(clients.size());
      clients.emplace_back([&, i] {
        results[i] = StreamCopies(port, i, spec, segment, stop, /*rounds=*/1,
                                  &streaming);
      });
    }
    for (int i = 0; i < 500 && streaming < level; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));
    last = FootprintOf(*learner);
    std::printf(
        "connections: %d actors registered, one segment each, streams open: "
        "%.1f MB, %d threads\n",
        level, last.rss_mb, last.threads);
  }
  stop = true;
  for (std::thread& client : clients) client.join();
  kill(*learner, SIGTERM);
  waitpid(*learner, nullptr, 0);
  std::filesystem::remove(port_file, error);
  for (const absl::Status& result : results) {
    if (!result.ok()) return Fail("connections", result);
  }
  if (streaming < max_actors) {
    return Fail("connections",
                absl::InternalError("not every client got its stream"));
  }
  std::filesystem::remove(port_file + ".log", error);
  std::printf(
      "RESULT connections actors=%d idle_rss_mb=%.1f rss_mb=%.1f "
      "per_actor_kb=%.1f threads=%d idle_threads=%d\n",
      max_actors, idle.rss_mb, last.rss_mb,
      (last.rss_mb - idle.rss_mb) * 1024 / max_actors, last.threads,
      idle.threads);
  return 0;
}

int RunActorBenchmark(const std::string& env_name, int envs, double seconds,
                      const NetworkConfig& network) {
  SetComputeThreads(1);
  absl::StatusOr<std::unique_ptr<Environment>> probe =
      MakeEnvironment(env_name);
  if (!probe.ok()) return Fail("actor", probe.status());
  std::unique_ptr<RawPhysics> physics = MakeRawPhysics(**probe);
  if (physics == nullptr) {
    return Fail("actor", absl::InvalidArgumentError(
                             absl::StrCat(env_name,
                                          " has no MuJoCo or Bullet model to "
                                          "compare with")));
  }
  absl::StatusOr<int64_t> episode_length = FixedActionEpisodeLength(**probe);
  if (!episode_length.ok()) return Fail("actor", episode_length.status());
  RegisterRawBenchmark("raw", *physics, *episode_length);
  FastestCollector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  const double raw = 1.0 / collector.Seconds("raw");

  // The `vantage actor` loop itself, paced by a learner that publishes a
  // version per batch of its data and otherwise only ingests.
  const EnvSpec spec = (*probe)->spec();
  const pb::RunConfig run = BenchRunConfig(env_name, network);
  absl::StatusOr<std::unique_ptr<ConsumingLearner>> learner =
      ConsumingLearner::Start(
          run, spec, FreshWeights(spec, network),
          /*steps_per_version=*/run.training().horizon() * envs);
  if (!learner.ok()) return Fail("actor", learner.status());
  RemoteActorConfig config;
  config.learner = absl::StrCat("127.0.0.1:", (*learner)->port());
  config.env = env_name;
  config.num_envs = envs;
  config.max_reconnects = 0;
  std::atomic<bool> stop{false};
  absl::Status acted;
  std::thread actor([&] { acted = RunRemoteActor(config, stop); });
  // Registration and the first segments, then the windows.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  const double streamed = FastestIngestRate(**learner, seconds);
  stop = true;
  actor.join();
  learner->reset();
  if (!acted.ok()) return Fail("actor", acted);
  std::printf(
      "actor: `vantage actor` with %d %s envs (batched inference, one "
      "thread) streaming %ld-step segments over loopback gRPC into a "
      "learner that only ingests, against bare physics stepping\n",
      envs, env_name.c_str(), static_cast<long>(kSegmentLength));
  std::printf(
      "RESULT actor env=%s envs=%d core=%s raw_steps_per_s=%.0f "
      "actor_steps_per_s=%.0f ratio=%.3f\n",
      env_name.c_str(), envs,
      network.recurrent()
          ? absl::StrCat(CoreName(network.core), ":", network.core_size).c_str()
          : "none",
      raw, streamed, streamed / raw);
  return 0;
}

}  // namespace vantage
