// The `vantage` command-line tool: one binary, one subcommand per task.

#include <benchmark/benchmark.h>

#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_join.h"
#include "bench/advantage_bench.h"
#include "bench/env_bench.h"
#include "deploy/cli/advantages_command.h"
#include "deploy/cli/env_commands.h"
#include "deploy/cli/train_command.h"

ABSL_FLAG(std::string, input, "",
          "advantages: JSON file with one rollout and the estimator settings");
ABSL_FLAG(bool, example, false,
          "advantages: print every estimator on a built-in rollout");
ABSL_FLAG(std::string, env, "",
          "rollout, bench env, train: environment name (see `vantage envs`) "
          "or mjcf:PATH; train defaults to InvertedPendulum");
ABSL_FLAG(std::string, mode, "local", "train: local (one process)");
ABSL_FLAG(std::string, algo, "ppo", "train: learning algorithm (ppo)");
ABSL_FLAG(std::string, estimator, "maxabs",
          "train: gae | max | min | maxabs | order:D");
ABSL_FLAG(double, rho, 0.4, "train: probability of the biased estimate");
ABSL_FLAG(std::vector<std::string>, ensemble,
          std::vector<std::string>({"1", "16", "64", "2048"}),
          "train: the path ensemble's k-step lengths");
ABSL_FLAG(int64_t, steps, 150000, "train: environment steps");
ABSL_FLAG(int, envs, 1, "train: environments (one rollout each per update)");
ABSL_FLAG(int64_t, horizon, 2048, "train: rollout length per environment");
ABSL_FLAG(int64_t, episodes, 10, "rollout: number of episodes");
ABSL_FLAG(uint64_t, seed, 0, "rollout, train: random seed");
ABSL_FLAG(int64_t, bench_steps, 2048, "bench advantages: rollout length T");
ABSL_FLAG(int64_t, bench_streams, 16,
          "bench advantages: number of env streams");

namespace vantage {
namespace {

constexpr int kUsageExitCode = 2;

using Command = std::function<int(const std::vector<std::string>& args)>;

int RunAdvantages(const std::vector<std::string>& args) {
  if (!args.empty()) {
    std::fprintf(stderr, "vantage advantages: unexpected argument '%s'\n",
                 args[0].c_str());
    return kUsageExitCode;
  }
  if (absl::GetFlag(FLAGS_example)) return RunAdvantagesExample();
  return RunAdvantagesCommand(absl::GetFlag(FLAGS_input));
}

// For commands that take no positional arguments.
int NoArguments(const char* command, const std::vector<std::string>& args) {
  if (args.empty()) return 0;
  std::fprintf(stderr, "vantage %s: unexpected argument '%s'\n", command,
               args[0].c_str());
  return kUsageExitCode;
}

int RunEnvs(const std::vector<std::string>& args) {
  if (int code = NoArguments("envs", args); code != 0) return code;
  return RunEnvsCommand();
}

int RunRollout(const std::vector<std::string>& args) {
  if (int code = NoArguments("rollout", args); code != 0) return code;
  return RunRolloutCommand(absl::GetFlag(FLAGS_env),
                           absl::GetFlag(FLAGS_episodes),
                           absl::GetFlag(FLAGS_seed));
}

int RunTrain(const std::vector<std::string>& args) {
  if (int code = NoArguments("train", args); code != 0) return code;
  TrainFlags flags;
  flags.mode = absl::GetFlag(FLAGS_mode);
  if (!absl::GetFlag(FLAGS_env).empty()) flags.env = absl::GetFlag(FLAGS_env);
  flags.algo = absl::GetFlag(FLAGS_algo);
  flags.estimator = absl::GetFlag(FLAGS_estimator);
  flags.rho = absl::GetFlag(FLAGS_rho);
  flags.ensemble.clear();
  for (const std::string& k : absl::GetFlag(FLAGS_ensemble)) {
    int64_t value = 0;
    if (!absl::SimpleAtoi(k, &value)) {
      std::fprintf(stderr,
                   "vantage train: --ensemble entry '%s' is not an "
                   "integer\n",
                   k.c_str());
      return kUsageExitCode;
    }
    flags.ensemble.push_back(value);
  }
  flags.steps = absl::GetFlag(FLAGS_steps);
  flags.seed = absl::GetFlag(FLAGS_seed);
  flags.envs = absl::GetFlag(FLAGS_envs);
  flags.horizon = absl::GetFlag(FLAGS_horizon);
  return RunTrainCommand(flags);
}

int RunBench(const std::vector<std::string>& args) {
  const std::map<std::string, std::function<int()>> benchmarks = {
      {"advantages",
       [] {
         const int64_t steps = absl::GetFlag(FLAGS_bench_steps);
         const int64_t streams = absl::GetFlag(FLAGS_bench_streams);
         if (steps < 1 || streams < 1) {
           std::fprintf(stderr,
                        "vantage bench advantages: --bench_steps and "
                        "--bench_streams must be >= 1\n");
           return kUsageExitCode;
         }
         return RunAdvantageBenchmark(steps, streams);
       }},
      {"env", [] { return RunEnvBenchmark(absl::GetFlag(FLAGS_env)); }},
  };
  std::vector<std::string> names;
  for (const auto& entry : benchmarks) names.push_back(entry.first);
  if (args.size() != 1 || benchmarks.count(args[0]) == 0) {
    std::fprintf(stderr, "vantage bench: name one benchmark of: %s\n",
                 absl::StrJoin(names, ", ").c_str());
    return kUsageExitCode;
  }
  return benchmarks.at(args[0])();
}

const std::map<std::string, Command>& Commands() {
  static const auto* commands = new std::map<std::string, Command>{
      {"advantages", RunAdvantages}, {"bench", RunBench}, {"envs", RunEnvs},
      {"rollout", RunRollout},       {"train", RunTrain},
  };
  return *commands;
}

std::string CommandNames() {
  std::vector<std::string> names;
  for (const auto& entry : Commands()) names.push_back(entry.first);
  return absl::StrJoin(names, ", ");
}

}  // namespace
}  // namespace vantage

int main(int argc, char** argv) {
  // Google Benchmark takes its own --benchmark_* flags out of argv first.
  // Interleaving the repetitions of all benchmarks spreads a noisy
  // machine's slow moments over all of them instead of skewing one ratio;
  // a later --benchmark_enable_random_interleaving=false still wins.
  std::vector<char*> args(argv, argv + argc);
  char interleave[] = "--benchmark_enable_random_interleaving=true";
  args.insert(args.begin() + 1, interleave);
  int args_count = static_cast<int>(args.size());
  benchmark::Initialize(&args_count, args.data());
  argc = args_count;
  argv = args.data();
  absl::SetProgramUsageMessage(
      "vantage <command> [flags]\n"
      "  advantages --input=FILE.json   estimates of one rollout as JSON\n"
      "  advantages --example           every estimator on a built-in rollout\n"
      "  train [--env --estimator --rho --steps --seed ...]   local PPO\n"
      "  envs                           registered environments\n"
      "  rollout --env=NAME --episodes=N --seed=S   random-policy episodes\n"
      "  bench advantages               path ensemble vs GAE benchmark\n"
      "  bench env --env=NAME           env layer vs raw physics benchmark\n");
  const std::vector<char*> positional = absl::ParseCommandLine(argc, argv);
  if (positional.size() < 2) {
    std::fprintf(stderr, "%s", absl::ProgramUsageMessage().data());
    return vantage::kUsageExitCode;
  }
  const std::string name = positional[1];
  const auto& commands = vantage::Commands();
  auto command = commands.find(name);
  if (command == commands.end()) {
    std::fprintf(stderr, "vantage: unknown command '%s'; commands: %s\n",
                 name.c_str(), vantage::CommandNames().c_str());
    return vantage::kUsageExitCode;
  }
  return command->second(
      std::vector<std::string>(positional.begin() + 2, positional.end()));
}
