#include "deploy/cli/bench_command.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "actor/envs/env_registry.h"
#include "bench/advantage_bench.h"
#include "bench/env_bench.h"
#include "bench/learner_bench.h"
#include "bench/malloc_bench.h"
#include "bench/recurrent_learner_bench.h"
#include "bench/train_bench.h"
#include "bench/transport_bench.h"
#include "common/util/malloc_settings.h"
#include "deploy/cli/command_line.h"
#include "deploy/cli/run_flags.h"
#include "deploy/cli/shared_flags.h"
#include "deploy/run/run_config.h"
#include "learner/algorithms/algorithm.h"
#include "learner/run/batch_memory.h"

ABSL_FLAG(int64_t, bench_steps, 2048, "advantages: rollout length T");
ABSL_FLAG(int64_t, bench_streams, 16, "advantages: number of env streams");
ABSL_FLAG(int32_t, bench_clients, 4,
          "ingest: loopback clients streaming segments; connections: actors "
          "connected (default 200)");
ABSL_FLAG(double, bench_seconds, 5.0,
          "ingest, actor: length of each timed window");
ABSL_FLAG(std::string, bench_replica_of, "",
          "learner: run as the second data-parallel replica of the `bench "
          "learner` whose rendezvous is this HOST:PORT (started by it)");
ABSL_FLAG(int64_t, bench_replica_minibatch, 0,
          "learner: the second replica's minibatch size in the "
          "learner_scaling sweep (set by it; 0: bench learner's shape)");
ABSL_FLAG(std::vector<std::string>, bench_minibatches,
          std::vector<std::string>({"64", "256", "1024", "4096"}),
          "learner_scaling: minibatch sizes (dividing 8192)");
ABSL_FLAG(std::vector<std::string>, bench_threads,
          std::vector<std::string>({"1", "2"}),
          "learner_scaling: intra-op thread counts of one learner");

namespace vantage {
namespace {

// `bench actor`'s setting unless told otherwise.
constexpr char kActorBenchEnv[] = "HalfCheetah";
constexpr int kActorBenchEnvs = 16;
// `bench train`'s run unless told otherwise: HalfCheetah with the
// baselines' PPO, about 30 updates of the default two actors.
constexpr char kTrainBenchEnv[] = "HalfCheetah";
constexpr int64_t kTrainBenchSteps = 122880;
constexpr int kConnectionsBenchActors = 200;
// `bench malloc`'s run unless told otherwise: the first-person maze preset's
// TRPO batches (8 x 500 frames), three updates, in one process.
constexpr char kMallocBenchEnv[] = "FirstPersonMaze";
constexpr int64_t kMallocBenchSteps = 12000;
constexpr int kMallocBenchEnvs = 8;
constexpr int64_t kMallocBenchHorizon = 500;

int Usage(const char* message) {
  std::fprintf(stderr, "vantage bench %s\n", message);
  return kUsageError;
}

// The bench's env and steps unless given; only the distributed main job.
// An error's message is a usage line.
absl::Status ApplyTrainBenchDefaults(RunRequest& request) {
  if (!request.resume.empty() || !request.run_dir.empty()) {
    return absl::InvalidArgumentError(
        "train: --run_dir and --resume are not for a benchmark");
  }
  pb::TrainingSettings& training = *request.flags.mutable_training();
  if (!training.has_env()) training.set_env(kTrainBenchEnv);
  if (!training.has_steps()) training.set_steps(kTrainBenchSteps);
  if (request.flags.has_mode() && request.flags.mode() != "distributed") {
    return absl::InvalidArgumentError(
        "train: times the distributed main job (no --mode=local)");
  }
  request.flags.set_mode("distributed");
  return absl::OkStatus();
}

// Both ways the main job can act unless told one: synchronous, and
// asynchronous with a policy lag of one version.
std::vector<RunRequest> TrainBenchModes(const RunRequest& request) {
  const pb::DistributedSettings& given = request.flags.distributed();
  if (given.has_sync() || given.has_max_policy_lag()) return {request};
  std::vector<RunRequest> modes;
  for (const auto& [sync, lag] :
       std::vector<std::pair<bool, int64_t>>{{true, 0}, {false, 1}}) {
    RunRequest& mode = modes.emplace_back(request);
    pb::DistributedSettings& d = *mode.flags.mutable_distributed();
    d.set_sync(sync);
    d.set_max_policy_lag(lag);
  }
  return modes;
}

// The shapes and sizes the machine's limit is computed for (every mode's
// run is the same but for sync and the policy lag).
void DescribeTrainBench(const ResolvedRun& run, const EnvSpec& spec,
                        TrainBenchConfig& bench) {
  const pb::RunConfig& config = run.config;
  const pb::DistributedSettings& resolved = config.distributed();
  bench.env = config.training().env();
  bench.learners = resolved.learners();
  bench.actors = resolved.actors();
  bench.envs_per_actor = resolved.envs_per_actor();
  bench.batch = config.training().horizon() * config.training().envs();
  bench.shape.observations = spec.observation_size;
  bench.shape.actions = spec.action_size;
  bench.shape.hidden.assign(config.training().hidden().begin(),
                            config.training().hidden().end());
  bench.shape.epochs = config.ppo().epochs();
  bench.shape.minibatches = config.ppo().minibatches();
  bench.a2c = AlgorithmNameOf(config) == "a2c";
  bench.spec = spec;
  bench.network = run.plan.learner.network;
  bench.a2c_config = run.plan.learner.algorithm.Get<A2cConfig>();
  bench.streams = config.training().envs();
}

// Resolves one mode's run and writes its config for the timed `vantage
// train`. An error's message is a usage line.
absl::Status AddTrainBenchRun(const RunRequest& mode_request,
                              TrainBenchConfig& bench) {
  absl::StatusOr<ResolvedRun> run = ResolveRunRequest(mode_request);
  if (!run.ok()) return run.status();
  const pb::RunConfig& config = run->config;
  const std::string algorithm = AlgorithmNameOf(config);
  if (algorithm != "ppo" && algorithm != "a2c") {
    return absl::InvalidArgumentError(
        "train: the limit counts PPO's epochs or A2C's update; use "
        "--algo=ppo or --algo=a2c");
  }
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(config.training().env(), EnvOptionsOf(config));
  if (!env.ok()) return env.status();
  TrainBenchRun timed;
  timed.config_path = absl::StrCat(
      std::filesystem::temp_directory_path().string(), "/vantage-bench-train-",
      ::getpid(), "-", bench.runs.size(), ".json");
  timed.sync = config.distributed().sync();
  timed.max_policy_lag = config.distributed().max_policy_lag();
  {
    std::ofstream file(timed.config_path, std::ios::trunc);
    file << RunConfigToJson(config);
    if (!file.flush()) {
      return absl::InvalidArgumentError("train: cannot write its run config");
    }
  }
  bench.runs.push_back(timed);
  DescribeTrainBench(*run, (*env)->spec(), bench);
  return absl::OkStatus();
}

// The run `vantage train` would make of the run flags given (with the
// bench's env and steps unless given), timed against the machine's limit.
int RunTrainBench() {
  absl::StatusOr<RunRequest> request = RunRequestFromFlags();
  if (!request.ok())
    return Usage(std::string(request.status().message()).c_str());
  if (absl::Status status = ApplyTrainBenchDefaults(*request); !status.ok()) {
    return Usage(std::string(status.message()).c_str());
  }
  TrainBenchConfig bench;
  for (const RunRequest& mode_request : TrainBenchModes(*request)) {
    if (absl::Status status = AddTrainBenchRun(mode_request, bench);
        !status.ok()) {
      return Usage(std::string(status.message()).c_str());
    }
  }
  const int code = RunTrainBenchmark(bench);
  std::error_code error;
  for (const TrainBenchRun& run : bench.runs) {
    std::filesystem::remove(run.config_path, error);
  }
  return code;
}

// The bench's run unless told otherwise (see kMallocBench*). An error's
// message is a usage line.
absl::Status ApplyMallocBenchDefaults(RunRequest& request) {
  if (!request.resume.empty() || !request.run_dir.empty()) {
    return absl::InvalidArgumentError(
        "malloc: --run_dir and --resume are not for a benchmark");
  }
  if (EnvironmentSetsMalloc(std::getenv("MALLOC_MMAP_MAX_"),
                            std::getenv("MALLOC_TRIM_THRESHOLD_"),
                            std::getenv("GLIBC_TUNABLES"))) {
    return absl::InvalidArgumentError(
        "malloc: compares glibc's defaults with vantage's settings; unset "
        "MALLOC_MMAP_MAX_, MALLOC_TRIM_THRESHOLD_ and GLIBC_TUNABLES's "
        "glibc.malloc tunables");
  }
  pb::TrainingSettings& training = *request.flags.mutable_training();
  if (!training.has_env()) training.set_env(kMallocBenchEnv);
  if (!training.has_steps()) training.set_steps(kMallocBenchSteps);
  if (!training.has_envs()) training.set_envs(kMallocBenchEnvs);
  if (!training.has_horizon()) training.set_horizon(kMallocBenchHorizon);
  // One process: its CPU time, faults and peak memory are the run's.
  request.flags.set_mode("local");
  if (request.algo.empty() &&
      request.flags.algorithm_case() == pb::RunConfig::ALGORITHM_NOT_SET) {
    request.algo = "trpo";
  }
  return absl::OkStatus();
}

// The run `vantage train` would make of the run flags given (with the
// bench's defaults), timed with glibc's malloc defaults and with vantage's.
int RunMallocBench() {
  absl::StatusOr<RunRequest> request = RunRequestFromFlags();
  if (!request.ok()) {
    return Usage(std::string(request.status().message()).c_str());
  }
  if (absl::Status status = ApplyMallocBenchDefaults(*request); !status.ok()) {
    return Usage(std::string(status.message()).c_str());
  }
  absl::StatusOr<ResolvedRun> run = ResolveRunRequest(*request);
  if (!run.ok()) return Usage(std::string(run.status().message()).c_str());
  absl::StatusOr<std::unique_ptr<Environment>> env =
      MakeEnvironment(run->config.training().env(), EnvOptionsOf(run->config));
  if (!env.ok()) return Usage(std::string(env.status().message()).c_str());
  LearnerConfig learner = run->plan.learner;
  learner.spec = (*env)->spec();
  MallocBenchConfig bench;
  bench.env = run->config.training().env();
  bench.batch_observation_bytes = BatchObservationBytes(learner);
  if (bench.batch_observation_bytes < kLargestMmapThreshold) {
    return Usage(
        absl::StrCat("malloc: a batch's observations take ",
                     bench.batch_observation_bytes,
                     " bytes, below glibc's largest mmap threshold (32 MiB): "
                     "vantage keeps glibc's defaults for such a run")
            .c_str());
  }
  bench.config_path =
      absl::StrCat(std::filesystem::temp_directory_path().string(),
                   "/vantage-bench-malloc-", ::getpid(), ".json");
  {
    std::ofstream file(bench.config_path, std::ios::trunc);
    file << RunConfigToJson(run->config);
    if (!file.flush()) return Usage("malloc: cannot write its run config");
  }
  const int code = RunMallocBenchmark(bench);
  std::error_code error;
  std::filesystem::remove(bench.config_path, error);
  return code;
}

int RunAdvantagesBench() {
  const int64_t steps = absl::GetFlag(FLAGS_bench_steps);
  const int64_t streams = absl::GetFlag(FLAGS_bench_streams);
  if (steps < 1 || streams < 1) {
    return Usage("advantages: --bench_steps and --bench_streams must be >= 1");
  }
  return RunAdvantageBenchmark(steps, streams);
}

// The recurrent core the run flags give (--core, --core_size), if any.
absl::StatusOr<NetworkConfig> CoreFromFlags() {
  absl::StatusOr<RunRequest> request = RunRequestFromFlags();
  if (!request.ok()) return request.status();
  const pb::TrainingSettings& given = request->flags.training();
  absl::StatusOr<Core> core =
      ParseCore(given.has_core() ? given.core() : "none");
  if (!core.ok()) return core.status();
  NetworkConfig network;
  network.core = *core;
  if (given.has_core_size()) network.core_size = given.core_size();
  return network;
}

int RunActorBench() {
  const std::string env =
      FlagGiven("env") ? absl::GetFlag(FLAGS_env) : kActorBenchEnv;
  const int envs =
      FlagGiven("envs") ? absl::GetFlag(FLAGS_envs) : kActorBenchEnvs;
  const double seconds = absl::GetFlag(FLAGS_bench_seconds);
  if (envs < 1 || !(seconds > 0)) {
    return Usage("actor: --envs must be >= 1 and --bench_seconds > 0");
  }
  absl::StatusOr<NetworkConfig> network = CoreFromFlags();
  if (!network.ok()) {
    return Usage(std::string(network.status().message()).c_str());
  }
  return RunActorBenchmark(env, envs, seconds, *network);
}

int RunEnvBench() {
  return RunEnvBenchmark(absl::GetFlag(FLAGS_env),
                         absl::GetFlag(FLAGS_env_kwargs));
}

int RunIngestBench() {
  const int clients = absl::GetFlag(FLAGS_bench_clients);
  const double seconds = absl::GetFlag(FLAGS_bench_seconds);
  if (clients < 1 || !(seconds > 0)) {
    return Usage(
        "ingest: --bench_clients must be >= 1 and --bench_seconds > 0");
  }
  return RunIngestBenchmark(clients, seconds);
}

int RunConnectionsBench() {
  const int actors = FlagGiven("bench_clients")
                         ? absl::GetFlag(FLAGS_bench_clients)
                         : kConnectionsBenchActors;
  if (actors < 4 || actors > 1000) {
    return Usage("connections: --bench_clients must be in [4, 1000]");
  }
  return RunConnectionsBenchmark(actors);
}

int RunLearnerBench() {
  const std::string replica_of = absl::GetFlag(FLAGS_bench_replica_of);
  absl::StatusOr<NetworkConfig> network = CoreFromFlags();
  if (!network.ok()) {
    return Usage(std::string(network.status().message()).c_str());
  }
  if (network->recurrent()) return RunRecurrentLearnerBenchmark(*network);
  return replica_of.empty()
             ? RunLearnerBenchmark()
             : RunLearnerBenchmarkReplica(
                   replica_of, absl::GetFlag(FLAGS_bench_replica_minibatch));
}

int RunLearnerScalingBench() {
  std::vector<int64_t> minibatches;
  for (const std::string& size : absl::GetFlag(FLAGS_bench_minibatches)) {
    int64_t value = 0;
    if (!absl::SimpleAtoi(size, &value)) {
      std::fprintf(stderr, "--bench_minibatches: '%s' is not a number\n",
                   size.c_str());
      return kUsageError;
    }
    minibatches.push_back(value);
  }
  std::vector<int> threads;
  for (const std::string& count : absl::GetFlag(FLAGS_bench_threads)) {
    int value = 0;
    if (!absl::SimpleAtoi(count, &value) || value < 1 || value > 256) {
      std::fprintf(stderr, "--bench_threads: '%s' is not 1..256\n",
                   count.c_str());
      return kUsageError;
    }
    threads.push_back(value);
  }
  if (minibatches.empty() || threads.empty()) {
    std::fprintf(stderr,
                 "--bench_minibatches and --bench_threads need a value\n");
    return kUsageError;
  }
  return RunLearnerScalingBenchmark(minibatches, threads);
}

const std::map<std::string, std::function<int()>>& Benchmarks() {
  static const auto* benchmarks =
      new std::map<std::string, std::function<int()>>{
          {"advantages", RunAdvantagesBench},
          {"actor", RunActorBench},
          {"env", RunEnvBench},
          {"ingest", RunIngestBench},
          {"train", RunTrainBench},
          {"connections", RunConnectionsBench},
          {"learner", RunLearnerBench},
          {"learner_scaling", RunLearnerScalingBench},
          {"malloc", RunMallocBench},
      };
  return *benchmarks;
}

std::string BenchmarkNames() {
  std::vector<std::string> names;
  for (const auto& entry : Benchmarks()) names.push_back(entry.first);
  return absl::StrJoin(names, ", ");
}

int RunBench(const std::vector<std::string>& args) {
  if (args.size() != 1 || Benchmarks().count(args[0]) == 0) {
    std::fprintf(stderr, "vantage bench: name one benchmark of: %s\n",
                 BenchmarkNames().c_str());
    return kUsageError;
  }
  return Benchmarks().at(args[0])();
}

// Google Benchmark's own flags (--benchmark_*) exist only here.
void InitializeGoogleBenchmark(std::vector<char*>& argv) {
  // Interleaving the repetitions of all benchmarks spreads a noisy
  // machine's slow moments over all of them instead of skewing one ratio.
  // Given first, so that the user's own flag still wins.
  static char interleave[] = "--benchmark_enable_random_interleaving=true";
  argv.insert(argv.begin() + 2, interleave);
  int argc = static_cast<int>(argv.size());
  argv.push_back(nullptr);
  benchmark::Initialize(&argc, argv.data());
  argv.resize(argc);
}

// The run flags mean what they mean to `vantage train`, but for these.
std::map<std::string, std::string> BenchFlagDefaults() {
  std::map<std::string, std::string> defaults =
      RunFlagDefaults(/*with_mode=*/false);
  defaults["env"] = absl::StrCat("actor: ", kActorBenchEnv,
                                 "; env: required; train: ", kTrainBenchEnv,
                                 "; malloc: ", kMallocBenchEnv);
  defaults["steps"] = absl::StrCat("train: ", kTrainBenchSteps,
                                   "; malloc: ", kMallocBenchSteps);
  defaults["envs"] =
      absl::StrCat("actor: ", kActorBenchEnvs, "; malloc: ", kMallocBenchEnvs);
  defaults["horizon"] += absl::StrCat("; malloc: ", kMallocBenchHorizon);
  return defaults;
}

}  // namespace

Command BenchCommand() {
  Command command;
  command.name = "bench";
  command.summary = "benchmarks: ratios against a baseline of the same run";
  command.usage =
      "vantage bench (advantages | actor | connections | env | ingest | "
      "learner | learner_scaling | malloc | train) [flags] [--benchmark_*]";
  command.description =
      "advantages: the path-ensemble estimators against GAE; env: the\n"
      "environment layer against raw physics (a MinAtar game: its bare\n"
      "rules; the raycast maze: its own rates only; a Python env: the same\n"
      "env in a plain Python loop); learner: a PPO update\n"
      "against a bare LibTorch loop; learner_scaling: PPO samples/s against\n"
      "the minibatch size, for one learner at each thread count and for two\n"
      "data-parallel replicas against one; ingest: the learner's segment "
      "ingest in\n"
      "actors; actor: a streaming actor against raw physics; connections: a\n"
      "learner's memory and threads per connected actor against its idle\n"
      "footprint; train: the distributed main job (`vantage train` with the\n"
      "run flags given) against the\n"
      "machine's limit from raw physics and vantage's own update (the bare\n"
      "loop's limit beside it); malloc: a local run on frames (`vantage\n"
      "train` with the run flags given; FirstPersonMaze's TRPO batches by\n"
      "default) with glibc's malloc defaults against the freed memory\n"
      "vantage keeps for batches above glibc's mmap threshold. Each ends\n"
      "with a\n"
      "line `RESULT <name> ... ratio=...` measured in the same run. Google\n"
      "Benchmark's --benchmark_* flags apply.";
  command.flags = {"bench_steps",
                   "bench_streams",
                   "bench_clients",
                   "bench_seconds",
                   "bench_replica_of",
                   "bench_replica_minibatch",
                   "bench_minibatches",
                   "bench_threads",
                   "env",
                   "envs"};
  // train: the run flags, as `vantage train` takes them.
  command.declared_flags = RunSettingFlags();
  for (const std::string& name : RunFlagNames(/*with_mode=*/false)) {
    if (std::find(command.flags.begin(), command.flags.end(), name) ==
        command.flags.end()) {
      command.flags.push_back(name);
    }
  }
  command.defaults = BenchFlagDefaults();
  command.example = "vantage bench env --env=Hopper";
  command.take_own_arguments = InitializeGoogleBenchmark;
  command.takes_arguments = true;
  command.run = RunBench;
  return command;
}

}  // namespace vantage
