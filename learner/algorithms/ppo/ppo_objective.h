#ifndef VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_OBJECTIVE_H_
#define VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_OBJECTIVE_H_

#include <ATen/core/Tensor.h>

namespace vantage {

struct PpoPolicyLoss {
  at::Tensor loss;           // scalar, to minimise
  at::Tensor clip_fraction;  // share of samples whose ratio left [1-e, 1+e]
  at::Tensor approx_kl;      // mean((r - 1) - log r) >= 0, no gradient
};

// PPO's clipped surrogate: with r = exp(log_prob - behaviour_log_prob),
// loss = -mean(min(r A, clip(r, 1 - clip, 1 + clip) A)). The behaviour
// log-probabilities are those the actor's (possibly stale) policy had when
// it acted, carried with the segment, not the learner's current ones.
PpoPolicyLoss PpoClippedPolicyLoss(const at::Tensor& log_prob,
                                   const at::Tensor& behaviour_log_prob,
                                   const at::Tensor& advantages, double clip);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_PPO_PPO_OBJECTIVE_H_
