#include "learner/algorithms/ppo/ppo_config.h"

#include "proto/run_config.pb.h"
#include "proto/settings_table.h"

namespace vantage {
namespace {

const SettingsTable<PpoConfig, pb::PpoSettings>& PpoTable() {
  using C = PpoConfig;
  static const auto* table = new SettingsTable<PpoConfig, pb::PpoSettings>(
      "ppo", {{"epochs", &C::epochs, AtLeast(1)},
              {"minibatches", &C::minibatches, AtLeast(1)},
              {"clip", &C::clip, Above(0), Below(1)},
              {"learning_rate", &C::learning_rate, Above(0)},
              {"max_grad_norm", &C::max_grad_norm, Above(0)},
              {"value_coef", &C::value_coef, AtLeast(0)},
              {"entropy_coef", &C::entropy_coef, AtLeast(0)},
              {"normalize_advantages", &C::normalize_advantages}});
  return *table;
}

}  // namespace

absl::Status PpoConfig::Validate() const { return PpoTable().Validate(*this); }

AlgorithmRunDefaults RunDefaults(const PpoConfig&) {
  AlgorithmRunDefaults defaults;
  defaults.horizon = 2048;
  defaults.gae_lambda = 0.95;
  return defaults;
}

PpoConfig FromSettings(const pb::PpoSettings& settings) {
  PpoConfig config;
  PpoTable().Read(settings, config);
  return config;
}

void ToSettings(const PpoConfig& config, pb::PpoSettings& settings) {
  PpoTable().Write(config, settings);
}

}  // namespace vantage
