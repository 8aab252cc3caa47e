#include "learner/algorithms/ppo/ppo_config.h"

#include "proto/run_config.pb.h"

namespace vantage {

absl::Status PpoConfig::Validate() const {
  if (epochs < 1) return absl::InvalidArgumentError("ppo.epochs must be >= 1");
  if (minibatches < 1) {
    return absl::InvalidArgumentError("ppo.minibatches must be >= 1");
  }
  if (!(clip > 0 && clip < 1)) {
    return absl::InvalidArgumentError("ppo.clip must be in (0, 1)");
  }
  if (!(learning_rate > 0)) {
    return absl::InvalidArgumentError("ppo.learning_rate must be > 0");
  }
  if (!(max_grad_norm > 0)) {
    return absl::InvalidArgumentError("ppo.max_grad_norm must be > 0");
  }
  if (!(value_coef >= 0)) {
    return absl::InvalidArgumentError("ppo.value_coef must be >= 0");
  }
  if (!(entropy_coef >= 0)) {
    return absl::InvalidArgumentError("ppo.entropy_coef must be >= 0");
  }
  return absl::OkStatus();
}

AlgorithmRunDefaults RunDefaults(const PpoConfig&) {
  AlgorithmRunDefaults defaults;
  defaults.horizon = 2048;
  defaults.gae_lambda = 0.95;
  return defaults;
}

PpoConfig FromSettings(const pb::PpoSettings& s) {
  PpoConfig c;
  if (s.has_epochs()) c.epochs = s.epochs();
  if (s.has_minibatches()) c.minibatches = s.minibatches();
  if (s.has_learning_rate()) c.learning_rate = s.learning_rate();
  if (s.has_clip()) c.clip = s.clip();
  if (s.has_entropy_coef()) c.entropy_coef = s.entropy_coef();
  if (s.has_value_coef()) c.value_coef = s.value_coef();
  if (s.has_max_grad_norm()) c.max_grad_norm = s.max_grad_norm();
  if (s.has_normalize_advantages()) {
    c.normalize_advantages = s.normalize_advantages();
  }
  return c;
}

void ToSettings(const PpoConfig& c, pb::PpoSettings& s) {
  s.set_epochs(c.epochs);
  s.set_minibatches(c.minibatches);
  s.set_learning_rate(c.learning_rate);
  s.set_clip(c.clip);
  s.set_entropy_coef(c.entropy_coef);
  s.set_value_coef(c.value_coef);
  s.set_max_grad_norm(c.max_grad_norm);
  s.set_normalize_advantages(c.normalize_advantages);
}

}  // namespace vantage
