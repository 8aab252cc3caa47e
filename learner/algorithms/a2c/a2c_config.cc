#include "learner/algorithms/a2c/a2c_config.h"

#include "proto/run_config.pb.h"

namespace vantage {

absl::Status A2cConfig::Validate() const {
  if (n < 1) return absl::InvalidArgumentError("a2c.n must be >= 1");
  if (steps_per_minibatch < 1) {
    return absl::InvalidArgumentError("a2c.steps_per_minibatch must be >= 1");
  }
  if (horizon() > (int64_t{1} << 24)) {
    return absl::InvalidArgumentError(
        "a2c.steps_per_minibatch x a2c.n must be at most 2^24 steps");
  }
  if (!(learning_rate > 0)) {
    return absl::InvalidArgumentError("a2c.learning_rate must be > 0");
  }
  if (!(max_grad_norm > 0)) {
    return absl::InvalidArgumentError("a2c.max_grad_norm must be > 0");
  }
  if (!(rmsprop_alpha > 0 && rmsprop_alpha < 1) || !(rmsprop_eps > 0)) {
    return absl::InvalidArgumentError(
        "a2c rmsprop alpha must be in (0, 1) and eps > 0");
  }
  if (!(value_coef >= 0)) {
    return absl::InvalidArgumentError("a2c.value_coef must be >= 0");
  }
  if (!(entropy_coef >= 0)) {
    return absl::InvalidArgumentError("a2c.entropy_coef must be >= 0");
  }
  return absl::OkStatus();
}

AlgorithmRunDefaults RunDefaults(const A2cConfig& config) {
  AlgorithmRunDefaults defaults;
  defaults.horizon = config.horizon();
  defaults.gae_lambda = 1.0;
  defaults.fixes_horizon = true;
  return defaults;
}

A2cConfig FromSettings(const pb::A2cSettings& s) {
  A2cConfig c;
  if (s.has_n()) c.n = s.n();
  if (s.has_steps_per_minibatch()) {
    c.steps_per_minibatch = s.steps_per_minibatch();
  }
  if (s.has_learning_rate()) c.learning_rate = s.learning_rate();
  if (s.has_entropy_coef()) c.entropy_coef = s.entropy_coef();
  if (s.has_value_coef()) c.value_coef = s.value_coef();
  if (s.has_max_grad_norm()) c.max_grad_norm = s.max_grad_norm();
  return c;
}

void ToSettings(const A2cConfig& c, pb::A2cSettings& s) {
  s.set_n(c.n);
  s.set_steps_per_minibatch(c.steps_per_minibatch);
  s.set_learning_rate(c.learning_rate);
  s.set_entropy_coef(c.entropy_coef);
  s.set_value_coef(c.value_coef);
  s.set_max_grad_norm(c.max_grad_norm);
}

}  // namespace vantage
