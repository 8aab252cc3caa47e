#include "learner/algorithms/trpo/trpo_config.h"

#include "proto/run_config.pb.h"
#include "proto/settings_table.h"

namespace vantage {
namespace {

const SettingsTable<TrpoConfig, pb::TrpoSettings>& TrpoTable() {
  using C = TrpoConfig;
  static const auto* table = new SettingsTable<TrpoConfig, pb::TrpoSettings>(
      "trpo", {{"max_kl", &C::max_kl, Above(0)},
               {"cg_damping", &C::cg_damping, AtLeast(0)},
               {"cg_iterations", &C::cg_iterations, AtLeast(1)},
               {"value_learning_rate", &C::value_learning_rate, Above(0)},
               {"value_epochs", &C::value_epochs, AtLeast(1)},
               {"entropy_coef", &C::entropy_coef, AtLeast(0)},
               {"linear_baseline", &C::linear_baseline},
               {"zero_baseline", &C::zero_baseline}});
  return *table;
}

}  // namespace

absl::Status TrpoConfig::Validate() const {
  if (absl::Status status = TrpoTable().Validate(*this); !status.ok()) {
    return status;
  }
  if (linear_baseline && zero_baseline) {
    return absl::InvalidArgumentError(
        "trpo.linear_baseline and trpo.zero_baseline are two different "
        "critics; set one of them");
  }
  // Not settings of a run: fixed by the code that makes the config.
  if (line_search_steps < 1) {
    return absl::InvalidArgumentError("trpo line search steps must be >= 1");
  }
  if (value_minibatch_size < 1) {
    return absl::InvalidArgumentError("trpo value minibatch size must be >= 1");
  }
  return absl::OkStatus();
}

AlgorithmRunDefaults RunDefaults(const TrpoConfig&) {
  AlgorithmRunDefaults defaults;
  defaults.horizon = 1024;
  defaults.gae_lambda = 0.98;
  return defaults;
}

TrpoConfig FromSettings(const pb::TrpoSettings& settings) {
  TrpoConfig config;
  TrpoTable().Read(settings, config);
  return config;
}

void ToSettings(const TrpoConfig& config, pb::TrpoSettings& settings) {
  TrpoTable().Write(config, settings);
}

}  // namespace vantage
