#include "actor/evaluation_config.h"

#include "proto/settings_table.h"

namespace vantage {
namespace {

const SettingsTable<EvaluationConfig, pb::EvaluationSettings>&
EvaluationTable() {
  using C = EvaluationConfig;
  static const auto* table =
      new SettingsTable<EvaluationConfig, pb::EvaluationSettings>(
          "evaluation",
          {{"eval_every", &C::every, AtLeast(0), std::nullopt, "(0: none)"},
           {"eval_episodes", &C::episodes, AtLeast(1), AtMost(100000)}},
          SettingNames::kFlag);
  return *table;
}

}  // namespace

absl::Status EvaluationConfig::Validate() const {
  return EvaluationTable().Validate(*this);
}

absl::Status ResolveEvaluationSettings(pb::RunConfig& run) {
  if (!run.has_evaluation()) return absl::OkStatus();
  pb::EvaluationSettings& settings = *run.mutable_evaluation();
  if (settings.has_eval_episodes() && !settings.has_eval_every()) {
    return FlagError("eval_episodes",
                     "needs --eval_every (updates between "
                     "evaluations, above 0)");
  }
  absl::StatusOr<EvaluationConfig> config =
      EvaluationTable().Resolve(EvaluationConfig(), settings);
  if (!config.ok()) return config.status();
  if (!config->enabled()) run.clear_evaluation();
  return absl::OkStatus();
}

EvaluationConfig EvaluationConfigOf(const pb::RunConfig& run) {
  EvaluationConfig config;
  if (run.has_evaluation()) EvaluationTable().Read(run.evaluation(), config);
  return config;
}

}  // namespace vantage
