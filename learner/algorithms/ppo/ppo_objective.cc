#include "learner/algorithms/ppo/ppo_objective.h"

#include <ATen/ATen.h>

namespace vantage {

PpoPolicyLoss PpoClippedPolicyLoss(const at::Tensor& log_prob,
                                   const at::Tensor& behaviour_log_prob,
                                   const at::Tensor& advantages, double clip) {
  const at::Tensor log_ratio = log_prob - behaviour_log_prob.detach();
  const at::Tensor ratio = at::exp(log_ratio);
  const at::Tensor unclipped = ratio * advantages;
  const at::Tensor clipped = ratio.clamp(1.0 - clip, 1.0 + clip) * advantages;
  PpoPolicyLoss out;
  out.loss = -at::min(unclipped, clipped).mean();
  const at::Tensor detached = ratio.detach();
  out.clip_fraction = ((detached - 1.0).abs() > clip).to(at::kFloat).mean();
  out.approx_kl = ((detached - 1.0) - log_ratio.detach()).mean();
  return out;
}

}  // namespace vantage
