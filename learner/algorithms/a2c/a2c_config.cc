#include "learner/algorithms/a2c/a2c_config.h"

#include "absl/strings/str_cat.h"
#include "proto/run_config.pb.h"
#include "proto/settings_table.h"

namespace vantage {

namespace {

const SettingsTable<A2cConfig, pb::A2cSettings>& A2cTable() {
  using C = A2cConfig;
  static const auto* table = new SettingsTable<A2cConfig, pb::A2cSettings>(
      "a2c", {{"n", &C::n, AtLeast(1)},
              {"steps_per_minibatch", &C::steps_per_minibatch, AtLeast(1)},
              {"learning_rate", &C::learning_rate, Above(0)},
              {"max_grad_norm", &C::max_grad_norm, Above(0)},
              {"rmsprop", &C::rmsprop},
              {"rmsprop_alpha", &C::rmsprop_alpha, Above(0), Below(1)},
              {"rmsprop_eps", &C::rmsprop_eps, Above(0)},
              {"value_coef", &C::value_coef, AtLeast(0)},
              {"entropy_coef", &C::entropy_coef, AtLeast(0)}});
  return *table;
}

}  // namespace

absl::Status A2cConfig::Validate() const {
  if (absl::Status status = A2cTable().Validate(*this); !status.ok()) {
    return status;
  }
  if (horizon() > (int64_t{1} << 24)) {
    return absl::InvalidArgumentError(
        "a2c.steps_per_minibatch x a2c.n must be at most 2^24 steps");
  }
  if (rmsprop != "tensorflow" && rmsprop != "pytorch") {
    return absl::InvalidArgumentError(absl::StrCat(
        "a2c.rmsprop must be tensorflow or pytorch, not '", rmsprop, "'"));
  }
  return absl::OkStatus();
}

AlgorithmRunDefaults RunDefaults(const A2cConfig& config) {
  AlgorithmRunDefaults defaults;
  defaults.horizon = config.horizon();
  defaults.gae_lambda = 1.0;
  defaults.fixes_horizon = true;
  defaults.horizon_multiple = config.steps_per_minibatch;
  return defaults;
}

A2cConfig FromSettings(const pb::A2cSettings& settings) {
  A2cConfig config;
  A2cTable().Read(settings, config);
  return config;
}

void ToSettings(const A2cConfig& config, pb::A2cSettings& settings) {
  A2cTable().Write(config, settings);
}

}  // namespace vantage
