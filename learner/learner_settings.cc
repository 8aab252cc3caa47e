#include "learner/learner_settings.h"

#include <string>

#include "absl/strings/str_cat.h"
#include "common/advantage/advantage_config.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/exploration/ex2_config.h"
#include "proto/settings_table.h"

namespace vantage {
namespace {

const SettingsTable<LearnerConfig, pb::TrainingSettings>& TrainingTable() {
  using C = LearnerConfig;
  static const auto* table =
      new SettingsTable<LearnerConfig, pb::TrainingSettings>(
          "training",
          {{"steps", &C::total_env_steps, AtLeast(1)},
           {"horizon", &C::horizon, AtLeast(1)},
           {"scale_rewards", &C::scale_rewards},
           {"normalize_observations", &C::normalize_observations},
           {"bootstrap_time_limits", &C::bootstrap_time_limits}},
          SettingNames::kFlag);
  return *table;
}

// The estimator's numbers; their rules are AdvantageConfig::Validate's
// (its statistic is a name, read below).
const SettingsTable<AdvantageConfig, pb::AdvantageSettings>& AdvantageTable() {
  using C = AdvantageConfig;
  static const auto* table =
      new SettingsTable<AdvantageConfig, pb::AdvantageSettings>(
          "advantage",
          {{"rho", &C::rho},
           {"ensemble", &C::ensemble},
           {"gamma", &C::gamma},
           {"gae_lambda", &C::lambda}},
          SettingNames::kFlag);
  return *table;
}

absl::StatusOr<AdvantageConfig> AdvantageConfigOf(const pb::RunConfig& run) {
  AdvantageConfig advantage;
  AdvantageTable().Read(run.advantage(), advantage);
  absl::StatusOr<Statistic> statistic =
      ParseStatistic(run.advantage().estimator());
  if (!statistic.ok()) return statistic.status();
  advantage.statistic = *statistic;
  return advantage;
}

}  // namespace

absl::Status ResolveLearnerTraining(const LearnerConfig& defaults,
                                    const AlgorithmRunDefaults& algorithm,
                                    const std::string& algorithm_name,
                                    pb::TrainingSettings& training) {
  LearnerConfig with_horizon = defaults;
  with_horizon.horizon = algorithm.horizon;
  absl::StatusOr<LearnerConfig> learner =
      TrainingTable().Resolve(with_horizon, training);
  if (!learner.ok()) return learner.status();
  if (algorithm.fixes_horizon && learner->horizon != algorithm.horizon) {
    return absl::InvalidArgumentError(
        absl::StrCat("--horizon is ", learner->horizon, " but ", algorithm_name,
                     "'s own settings make it ", algorithm.horizon,
                     "; change those (see `vantage help train`)"));
  }
  return absl::OkStatus();
}

absl::Status ResolveAdvantageSettings(const AlgorithmRunDefaults& algorithm,
                                      pb::AdvantageSettings& advantage) {
  AdvantageConfig defaults;
  defaults.lambda = algorithm.gae_lambda;
  if (!advantage.has_estimator()) {
    advantage.set_estimator(StatisticName(defaults.statistic));
  }
  absl::StatusOr<Statistic> statistic = ParseStatistic(advantage.estimator());
  if (!statistic.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("--estimator: ", statistic.status().message()));
  }
  return AdvantageTable().Resolve(defaults, advantage).status();
}

absl::StatusOr<LearnerConfig> LearnerConfigOf(const pb::RunConfig& run) {
  const pb::TrainingSettings& training = run.training();
  LearnerConfig learner;
  TrainingTable().Read(training, learner);
  // The batch: one rollout per env stream of the run.
  learner.rollouts_per_batch = training.envs();
  learner.max_segment_steps = training.segment_length();
  learner.max_policy_lag = run.distributed().max_policy_lag();
  learner.seed = training.seed();
  absl::StatusOr<AdvantageConfig> advantage = AdvantageConfigOf(run);
  if (!advantage.ok()) return advantage.status();
  learner.advantage = *std::move(advantage);
  learner.algorithm = AlgorithmConfigOf(run);
  learner.exploration = ExplorationConfigOf(run);
  return learner;
}

}  // namespace vantage
