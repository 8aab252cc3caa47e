#include "learner/algorithms/trpo/trpo_config.h"

#include "proto/run_config.pb.h"

namespace vantage {

absl::Status TrpoConfig::Validate() const {
  if (!(max_kl > 0))
    return absl::InvalidArgumentError("trpo.max_kl must be > 0");
  if (!(cg_damping >= 0)) {
    return absl::InvalidArgumentError("trpo.cg_damping must be >= 0");
  }
  if (cg_iterations < 1) {
    return absl::InvalidArgumentError("trpo.cg_iterations must be >= 1");
  }
  if (line_search_steps < 1) {
    return absl::InvalidArgumentError("trpo line search steps must be >= 1");
  }
  if (!(value_learning_rate > 0)) {
    return absl::InvalidArgumentError("trpo.value_learning_rate must be > 0");
  }
  if (value_epochs < 1) {
    return absl::InvalidArgumentError("trpo.value_epochs must be >= 1");
  }
  if (value_minibatch_size < 1) {
    return absl::InvalidArgumentError("trpo value minibatch size must be >= 1");
  }
  if (!(entropy_coef >= 0)) {
    return absl::InvalidArgumentError("trpo.entropy_coef must be >= 0");
  }
  return absl::OkStatus();
}

AlgorithmRunDefaults RunDefaults(const TrpoConfig&) {
  AlgorithmRunDefaults defaults;
  defaults.horizon = 1024;
  defaults.gae_lambda = 0.98;
  return defaults;
}

TrpoConfig FromSettings(const pb::TrpoSettings& s) {
  TrpoConfig c;
  if (s.has_max_kl()) c.max_kl = s.max_kl();
  if (s.has_cg_iterations()) c.cg_iterations = s.cg_iterations();
  if (s.has_cg_damping()) c.cg_damping = s.cg_damping();
  if (s.has_entropy_coef()) c.entropy_coef = s.entropy_coef();
  if (s.has_value_learning_rate()) {
    c.value_learning_rate = s.value_learning_rate();
  }
  if (s.has_value_epochs()) c.value_epochs = s.value_epochs();
  return c;
}

void ToSettings(const TrpoConfig& c, pb::TrpoSettings& s) {
  s.set_max_kl(c.max_kl);
  s.set_cg_iterations(c.cg_iterations);
  s.set_cg_damping(c.cg_damping);
  s.set_entropy_coef(c.entropy_coef);
  s.set_value_learning_rate(c.value_learning_rate);
  s.set_value_epochs(c.value_epochs);
}

}  // namespace vantage
