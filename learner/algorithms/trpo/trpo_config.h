#ifndef VANTAGE_LEARNER_ALGORITHMS_TRPO_TRPO_CONFIG_H_
#define VANTAGE_LEARNER_ALGORITHMS_TRPO_TRPO_CONFIG_H_

#include "absl/status/status.h"
#include "learner/algorithms/run_defaults.h"

namespace vantage {
namespace pb {
class TrpoSettings;
}  // namespace pb

// Defaults of the baselines' TRPO for MuJoCo.
struct TrpoConfig {
  double max_kl = 0.01;
  int cg_iterations = 10;
  double cg_damping = 0.1;
  int line_search_steps = 10;  // step fractions 1, 1/2, 1/4, ...
  double entropy_coef = 0.0;
  bool normalize_advantages = true;  // over the batch, after rho mixing
  // The value function is fitted by Adam on the targets V + GAE.
  double value_learning_rate = 1e-3;
  int value_epochs = 5;
  int value_minibatch_size = 64;
  // The learner's LinearCritic values the states instead of the value
  // network, which then is never fitted (value_* unused).
  bool linear_baseline = false;
  // No critic: every state is valued 0 (rllab's ZeroBaseline); the value
  // network is never used or fitted.
  bool zero_baseline = false;

  // Names the rule a field breaks as its run-config field (trpo.max_kl).
  absl::Status Validate() const;
};

// The baselines' TRPO: 1024-step rollouts, GAE lambda 0.98.
AlgorithmRunDefaults RunDefaults(const TrpoConfig& config);

// The given settings over the defaults above, and every field back.
TrpoConfig FromSettings(const pb::TrpoSettings& settings);
void ToSettings(const TrpoConfig& config, pb::TrpoSettings& settings);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_TRPO_TRPO_CONFIG_H_
