#include "deploy/cli/advantages_command.h"

#include <ATen/ATen.h>

#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "absl/flags/flag.h"
#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"
#include "deploy/cli/advantage_request.h"

ABSL_FLAG(std::string, input, "",
          "JSON file with one rollout and the estimator settings");
ABSL_FLAG(bool, example, false,
          "print every estimator on a built-in rollout instead");

namespace vantage {
namespace {

// Everything that goes wrong here is the input's fault.
int Fail(const absl::Status& status) {
  return CommandFailure("advantages", kUsageError,
                        std::string(status.message()));
}

// 12 steps of one stream: an episode that terminates after step 4, one that
// a time limit truncates after step 8, and one cut by the rollout's end.
constexpr char kExampleRollout[] = R"json({
  "gamma": 0.9, "lambda": 0.95, "ensemble": [1, 2, 4, 16],
  "statistic": "maxabs", "rho": 0.5, "seed": 7,
  "rewards":  [0, 0, 1, 0, -2,   0, 0.5, 0, 1,   0, 0, 3],
  "values":   [0.2, 0.4, 0.9, -1.0, -1.5,   0.6, 0.8, 0.7, 0.9,   0.5, 1.2, 2.0],
  "terminated": [false, false, false, false, true,
                 false, false, false, false,  false, false, false],
  "truncated":  [false, false, false, false, false,
                 false, false, false, true,   false, false, false],
  "truncation_values": [0, 0, 0, 0, 0,  0, 0, 0, 1.1,  0, 0, 0],
  "last_value": 1.5
})json";

int RunAdvantagesCommand(const std::string& input_path) {
  if (input_path.empty()) {
    return Fail(absl::InvalidArgumentError(
        "--input=FILE.json is required (or --example for a built-in one)"));
  }
  std::ifstream file(input_path);
  if (!file) {
    return Fail(absl::NotFoundError(
        absl::StrFormat("cannot open --input file '%s'", input_path)));
  }
  std::stringstream contents;
  contents << file.rdbuf();
  absl::StatusOr<AdvantageRequest> request =
      ParseAdvantageRequest(contents.str());
  if (!request.ok()) return Fail(request.status());
  std::mt19937_64 rng(request->seed);
  absl::StatusOr<Advantages> advantages =
      ComputeAdvantages(request->inputs, request->config, rng);
  if (!advantages.ok()) return Fail(advantages.status());
  std::printf("%s\n", AdvantagesToJson(*advantages).c_str());
  return 0;
}

int RunAdvantagesExample() {
  absl::StatusOr<AdvantageRequest> request =
      ParseAdvantageRequest(kExampleRollout);
  if (!request.ok()) return Fail(request.status());
  const AdvantageConfig& config = request->config;
  const AdvantageInputs& in = request->inputs;
  absl::StatusOr<at::Tensor> ksteps =
      ComputeKStepEstimates(in, config.gamma, config.ensemble);
  if (!ksteps.ok()) return Fail(ksteps.status());
  const int64_t steps = in.rewards.size(0);

  const std::vector<std::string> statistics = {"gae", "max", "min", "maxabs",
                                               "order:2"};
  std::vector<at::Tensor> columns;
  for (const std::string& name : statistics) {
    AdvantageConfig with_statistic = config;
    with_statistic.statistic = *ParseStatistic(name);
    absl::StatusOr<at::Tensor> column =
        ComputeBiasedAdvantage(in, with_statistic);
    if (!column.ok()) return Fail(column.status());
    columns.push_back(*column);
  }

  std::printf(
      "Advantage estimates of a built-in rollout (gamma=%g, lambda=%g).\n"
      "Episodes: t=0..4 terminated, t=5..8 truncated by a time limit "
      "(V(final obs)=1.1), t=9..11 cut by the rollout's end (V(s_T)=1.5).\n\n",
      config.gamma, config.lambda);
  std::printf("%3s %6s %6s %5s |", "t", "r", "V", "end");
  for (int64_t k : config.ensemble) {
    std::printf(" %8s", absl::StrFormat("A^(%d)", k).c_str());
  }
  std::printf(" |");
  for (const std::string& name : statistics) {
    std::printf(" %8s", name.c_str());
  }
  std::printf("\n");
  for (int64_t t = 0; t < steps; ++t) {
    const char* end = in.terminated[t][0].item<bool>()  ? "term"
                      : in.truncated[t][0].item<bool>() ? "trunc"
                      : t + 1 == steps                  ? "T"
                                                        : "";
    std::printf("%3ld %6.2f %6.2f %5s |", static_cast<long>(t),
                in.rewards[t][0].item<double>(), in.values[t][0].item<double>(),
                end);
    for (size_t m = 0; m < config.ensemble.size(); ++m) {
      std::printf(" %8.4f", (*ksteps)[m][t][0].item<double>());
    }
    std::printf(" |");
    for (const at::Tensor& column : columns) {
      std::printf(" %8.4f", column[t][0].item<double>());
    }
    std::printf("\n");
  }
  std::printf(
      "\nThe policy uses `statistic` with probability rho per sample and GAE "
      "otherwise; the critic always regresses on V + GAE.\n"
      "Try your own rollout: vantage advantages --input=FILE.json\n");
  return 0;
}

int RunAdvantages(const std::vector<std::string>&) {
  if (absl::GetFlag(FLAGS_example)) return RunAdvantagesExample();
  return RunAdvantagesCommand(absl::GetFlag(FLAGS_input));
}

}  // namespace

Command AdvantagesCommand() {
  Command command;
  command.name = "advantages";
  command.summary = "the estimators of one rollout, as JSON";
  command.usage = "vantage advantages (--input=FILE.json | --example)";
  command.description =
      "Computes GAE, every k-step estimate of the path ensemble and the\n"
      "biased statistic with its rho mask for one rollout given as JSON\n"
      "(rewards, values, terminated, truncated, truncation_values,\n"
      "last_value, gamma, lambda, ensemble, statistic, rho, seed), and prints\n"
      "them as JSON; --example prints a table of every estimator on a\n"
      "built-in rollout with a termination, a truncation and a rollout end.";
  command.flags = {"input", "example"};
  command.example = "vantage advantages --example";
  command.run = RunAdvantages;
  return command;
}

}  // namespace vantage
