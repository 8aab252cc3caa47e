#include "deploy/cli/bench_command.h"

#include <benchmark/benchmark.h>

#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "bench/advantage_bench.h"
#include "bench/env_bench.h"
#include "bench/learner_bench.h"
#include "bench/transport_bench.h"
#include "deploy/cli/command_line.h"
#include "deploy/cli/shared_flags.h"

ABSL_FLAG(int64_t, bench_steps, 2048, "advantages: rollout length T");
ABSL_FLAG(int64_t, bench_streams, 16, "advantages: number of env streams");
ABSL_FLAG(int32_t, bench_clients, 4,
          "ingest: loopback clients streaming segments");
ABSL_FLAG(double, bench_seconds, 5.0,
          "ingest, actor: length of each timed window");

namespace vantage {
namespace {

// `bench actor`'s setting unless told otherwise.
constexpr char kActorBenchEnv[] = "HalfCheetah";
constexpr int kActorBenchEnvs = 16;

int Usage(const char* message) {
  std::fprintf(stderr, "vantage bench %s\n", message);
  return kUsageError;
}

const std::map<std::string, std::function<int()>>& Benchmarks() {
  static const auto* benchmarks = new std::map<std::string,
                                               std::function<int()>>{
      {"advantages",
       [] {
         const int64_t steps = absl::GetFlag(FLAGS_bench_steps);
         const int64_t streams = absl::GetFlag(FLAGS_bench_streams);
         if (steps < 1 || streams < 1) {
           return Usage(
               "advantages: --bench_steps and --bench_streams must be >= 1");
         }
         return RunAdvantageBenchmark(steps, streams);
       }},
      {"actor",
       [] {
         const std::string env =
             FlagGiven("env") ? absl::GetFlag(FLAGS_env) : kActorBenchEnv;
         const int envs =
             FlagGiven("envs") ? absl::GetFlag(FLAGS_envs) : kActorBenchEnvs;
         const double seconds = absl::GetFlag(FLAGS_bench_seconds);
         if (envs < 1 || !(seconds > 0)) {
           return Usage("actor: --envs must be >= 1 and --bench_seconds > 0");
         }
         return RunActorBenchmark(env, envs, seconds);
       }},
      {"env", [] { return RunEnvBenchmark(absl::GetFlag(FLAGS_env)); }},
      {"ingest",
       [] {
         const int clients = absl::GetFlag(FLAGS_bench_clients);
         const double seconds = absl::GetFlag(FLAGS_bench_seconds);
         if (clients < 1 || !(seconds > 0)) {
           return Usage(
               "ingest: --bench_clients must be >= 1 and --bench_seconds > "
               "0");
         }
         return RunIngestBenchmark(clients, seconds);
       }},
      {"learner", [] { return RunLearnerBenchmark(); }},
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

}  // namespace

Command BenchCommand() {
  Command command;
  command.name = "bench";
  command.summary = "benchmarks: ratios against a baseline of the same run";
  command.usage =
      "vantage bench (advantages | actor | env | ingest | learner) [flags] "
      "[--benchmark_*]";
  command.description =
      "advantages: the path-ensemble estimators against GAE; env: the\n"
      "environment layer against raw physics; learner: a PPO update against\n"
      "a bare LibTorch loop; ingest: the learner's segment ingest in actors;\n"
      "actor: a streaming actor against raw physics. Each ends with a line\n"
      "`RESULT <name> ... ratio=...` measured in the same run. Google\n"
      "Benchmark's --benchmark_* flags apply.";
  command.flags = {"bench_steps",   "bench_streams", "bench_clients",
                   "bench_seconds", "env",           "envs"};
  command.defaults = {
      {"env", absl::StrCat("actor: ", kActorBenchEnv, "; env: required")},
      {"envs", absl::StrCat("actor: ", kActorBenchEnvs)}};
  command.example = "vantage bench env --env=Hopper";
  command.take_own_arguments = InitializeGoogleBenchmark;
  command.takes_arguments = true;
  command.run = RunBench;
  return command;
}

}  // namespace vantage
