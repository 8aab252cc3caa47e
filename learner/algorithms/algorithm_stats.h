#ifndef VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_STATS_H_
#define VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_STATS_H_

namespace vantage {

// Means over the update's gradient steps. NaN where an algorithm has no
// such quantity (A2C and TRPO clip nothing).
struct AlgorithmStats {
  double policy_loss = 0.0;
  double value_loss = 0.0;
  double entropy = 0.0;
  double approx_kl = 0.0;  // between the policy before and after
  double clip_fraction = 0.0;
  // The largest global gradient norm (before clipping) of any gradient step
  // of the policy; NaN where the algorithm takes none (TRPO's natural
  // gradient step).
  double max_gradient_norm = 0.0;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_STATS_H_
