#ifndef VANTAGE_COMMON_ROLLOUT_VALUE_LIMITS_H_
#define VANTAGE_COMMON_ROLLOUT_VALUE_LIMITS_H_

#include "absl/status/status.h"

namespace vantage {

// Magnitudes no honest actor sends. Finite numbers this large would still
// overflow the learner's sums and losses (a reward of 3e38 turns every
// weight into NaN), so they are refused with the field's name. The
// defaults are far above what any registered environment produces.
struct ValueLimits {
  double max_abs_observation = 1e6;
  double max_abs_action = 1e6;
  double max_abs_reward = 1e6;
  // Gaussian log-densities can be positive; |log p| beyond this means a
  // broken or hostile policy, not a confident one.
  double max_abs_log_prob = 1e5;

  // Every limit must be > 0 (and may be infinite: no limit).
  absl::Status Validate() const;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_ROLLOUT_VALUE_LIMITS_H_
