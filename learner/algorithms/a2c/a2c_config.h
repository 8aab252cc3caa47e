#ifndef VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_CONFIG_H_
#define VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_CONFIG_H_

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "learner/algorithms/run_defaults.h"

namespace vantage {
namespace pb {
class A2cSettings;
}  // namespace pb

// Defaults of the baselines' A2C the paper builds on (but for rmsprop).
struct A2cConfig {
  // The paper's path-ensemble trick: rollouts of steps_per_minibatch * n
  // steps (longer paths for the k-step estimates), updated as n
  // consecutive minibatches of steps_per_minibatch steps each. n = 1 is the
  // original A2C.
  int n = 4;
  int steps_per_minibatch = 5;  // A2C's rollout length
  double learning_rate = 7e-4;  // decays linearly to 0 over the run
  // How RMSProp computes its step: "pytorch" (torch::optim::RMSprop) or
  // "tensorflow" (TensorflowRmsprop, the baselines' arithmetic), whose tiny
  // first steps cost short runs (60k steps of Breakout reach 0.9 instead
  // of 3.3) and which did not stop the policy collapses of longer runs
  // (bench/results/README.md (e)).
  std::string rmsprop = "pytorch";
  double rmsprop_alpha = 0.99;
  double rmsprop_eps = 1e-5;
  double max_grad_norm = 0.5;
  double value_coef = 0.5;
  double entropy_coef = 0.01;

  // The rollout length A2C updates from: n minibatches.
  int64_t horizon() const {
    return static_cast<int64_t>(steps_per_minibatch) * n;
  }
  // Names the rule a field breaks as its run-config field (a2c.n).
  absl::Status Validate() const;
};

// The baselines' A2C: rollouts of horizon() steps, plain n-step returns
// (GAE lambda 1).
AlgorithmRunDefaults RunDefaults(const A2cConfig& config);

// The given settings over the defaults above, and every field back.
A2cConfig FromSettings(const pb::A2cSettings& settings);
void ToSettings(const A2cConfig& config, pb::A2cSettings& settings);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_A2C_A2C_CONFIG_H_
