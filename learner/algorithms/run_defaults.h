#ifndef VANTAGE_LEARNER_ALGORITHMS_RUN_DEFAULTS_H_
#define VANTAGE_LEARNER_ALGORITHMS_RUN_DEFAULTS_H_

#include <cstdint>

namespace vantage {

// The run settings outside its own section whose defaults an algorithm
// chooses: what its baselines' setup uses with it.
struct AlgorithmRunDefaults {
  int64_t horizon = 0;      // rollout length per stream
  double gae_lambda = 0.0;  // of the normal (GAE) estimate
  // The algorithm's own settings fix the horizon (A2C's n minibatches of
  // steps_per_minibatch steps): a run may not choose another one.
  bool fixes_horizon = false;
  // Its updates split each rollout into minibatches of this many steps
  // (A2C's), so the horizon must be a multiple of it.
  int64_t horizon_multiple = 1;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_RUN_DEFAULTS_H_
