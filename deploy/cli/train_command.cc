#include "deploy/cli/train_command.h"

#include <ATen/Parallel.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "deploy/local_training.h"

namespace vantage {
namespace {

int Fail(const std::string& message) {
  std::fprintf(stderr, "vantage train: %s\n", message.c_str());
  return 2;
}

}  // namespace

int RunTrainCommand(const TrainFlags& flags) {
  if (flags.mode != "local") {
    return Fail(
        absl::StrCat("unknown --mode='", flags.mode, "'; available: local"));
  }
  if (flags.algo != "ppo") {
    return Fail(
        absl::StrCat("unknown --algo='", flags.algo, "'; available: ppo"));
  }
  if (flags.steps < 1 || flags.envs < 1 || flags.horizon < 1) {
    return Fail("--steps, --envs and --horizon must be >= 1");
  }
  absl::StatusOr<Statistic> statistic = ParseStatistic(flags.estimator);
  if (!statistic.ok()) {
    return Fail(absl::StrCat("--estimator: ", statistic.status().message()));
  }
  LocalTrainingConfig config;
  config.env = flags.env;
  config.num_envs = flags.envs;
  config.total_env_steps = flags.steps;
  config.seed = flags.seed;
  config.learner.horizon = flags.horizon;
  config.learner.advantage.statistic = *statistic;
  config.learner.advantage.rho = flags.rho;
  config.learner.advantage.ensemble = flags.ensemble;
  if (absl::Status status = config.learner.advantage.Validate(); !status.ok()) {
    return Fail(std::string(status.message()));
  }
  at::set_num_threads(1);
  std::printf(
      "training %s with %s, estimator %s (rho %g, ensemble %s), "
      "%ld steps, seed %lu\n",
      flags.env.c_str(), flags.algo.c_str(), flags.estimator.c_str(), flags.rho,
      absl::StrJoin(flags.ensemble, ",").c_str(),
      static_cast<long>(flags.steps), static_cast<unsigned long>(flags.seed));
  const auto start = std::chrono::steady_clock::now();
  double last_mean = std::nan("");
  int64_t last_steps = 0;
  const absl::Status status = RunLocalTraining(
      config, [&](const UpdateStats& stats, double mean_return) {
        const double seconds = std::chrono::duration<double>(
                                   std::chrono::steady_clock::now() - start)
                                   .count();
        last_mean = mean_return;
        last_steps = stats.env_steps;
        std::printf(
            "update %3ld steps %7ld  return(last100) %8.1f  policy_loss %7.4f "
            " value_loss %8.3f  entropy %6.3f  kl %.4f  clip %.3f  "
            "biased %.2f  sps %.0f\n",
            static_cast<long>(stats.policy_version),
            static_cast<long>(stats.env_steps), mean_return,
            stats.ppo.policy_loss, stats.ppo.value_loss, stats.ppo.entropy,
            stats.ppo.approx_kl, stats.ppo.clip_fraction, stats.biased_fraction,
            stats.env_steps / seconds);
        std::fflush(stdout);
      });
  if (!status.ok()) return Fail(std::string(status.message()));
  std::printf(
      "RESULT train env=%s algo=%s estimator=%s rho=%g steps=%ld "
      "mean_return=%.1f\n",
      flags.env.c_str(), flags.algo.c_str(), flags.estimator.c_str(), flags.rho,
      static_cast<long>(last_steps), last_mean);
  return 0;
}

}  // namespace vantage
