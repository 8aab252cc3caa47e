#ifndef VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_CONFIG_H_
#define VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_CONFIG_H_

#include "absl/status/status.h"
#include "learner/algorithms/run_defaults.h"

namespace vantage {
namespace pb {
class PpoSettings;
}  // namespace pb

// Defaults of the paper's baselines setup for MuJoCo.
struct PpoConfig {
  int epochs = 10;
  int minibatches = 32;  // per epoch
  double clip = 0.2;
  double learning_rate = 3e-4;  // decays linearly to 0 over the run
  double max_grad_norm = 0.5;
  double value_coef = 0.5;
  double entropy_coef = 0.0;
  bool normalize_advantages = true;  // per minibatch, after rho mixing

  // Names the rule a field breaks as its run-config field (ppo.epochs).
  absl::Status Validate() const;
};

// The baselines' PPO: 2048-step rollouts, GAE lambda 0.95.
AlgorithmRunDefaults RunDefaults(const PpoConfig& config);

// The given settings over the defaults above, and every field back.
PpoConfig FromSettings(const pb::PpoSettings& settings);
void ToSettings(const PpoConfig& config, pb::PpoSettings& settings);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_CONFIG_H_
