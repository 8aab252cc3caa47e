#include "learner/algorithms/a2c/a2c_config.h"

#include "absl/strings/str_cat.h"
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
  if (rmsprop != "tensorflow" && rmsprop != "pytorch") {
    return absl::InvalidArgumentError(absl::StrCat(
        "a2c.rmsprop must be tensorflow or pytorch, not '", rmsprop, "'"));
  }
  if (!(rmsprop_alpha > 0 && rmsprop_alpha < 1)) {
    return absl::InvalidArgumentError("a2c.rmsprop_alpha must be in (0, 1)");
  }
  if (!(rmsprop_eps > 0)) {
    return absl::InvalidArgumentError("a2c.rmsprop_eps must be > 0");
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
  if (s.has_rmsprop()) c.rmsprop = s.rmsprop();
  if (s.has_rmsprop_alpha()) c.rmsprop_alpha = s.rmsprop_alpha();
  if (s.has_rmsprop_eps()) c.rmsprop_eps = s.rmsprop_eps();
  return c;
}

void ToSettings(const A2cConfig& c, pb::A2cSettings& s) {
  s.set_n(c.n);
  s.set_steps_per_minibatch(c.steps_per_minibatch);
  s.set_learning_rate(c.learning_rate);
  s.set_entropy_coef(c.entropy_coef);
  s.set_value_coef(c.value_coef);
  s.set_max_grad_norm(c.max_grad_norm);
  s.set_rmsprop(c.rmsprop);
  s.set_rmsprop_alpha(c.rmsprop_alpha);
  s.set_rmsprop_eps(c.rmsprop_eps);
}

}  // namespace vantage
