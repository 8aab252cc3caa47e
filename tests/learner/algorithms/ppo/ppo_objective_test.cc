#include "learner/algorithms/ppo/ppo_objective.h"

#include <ATen/ATen.h>

#include <cmath>

#include "gtest/gtest.h"

namespace vantage {
namespace {

// Ratios r = [1.0, 1.5, 0.5, 1.1], advantages [1, 1, -1, -2], clip 0.2:
// min(rA, clip(r)A) = [1, 1.2, -0.8, -2.2], mean -0.2, so the loss is 0.2.
TEST(PpoObjectiveTest, HandMadeBatchUsesTheBehaviourLogProbs) {
  const at::Tensor ratios = at::tensor({1.0, 1.5, 0.5, 1.1}, at::kDouble);
  // Stale behaviour log-probabilities from an older policy version.
  const at::Tensor behaviour =
      at::tensor({-1.0, -2.0, -0.5, -3.0}, at::kDouble);
  const at::Tensor log_prob =
      (behaviour + at::log(ratios)).detach().set_requires_grad(true);
  const at::Tensor advantages = at::tensor({1.0, 1.0, -1.0, -2.0}, at::kDouble);
  const PpoPolicyLoss out =
      PpoClippedPolicyLoss(log_prob, behaviour, advantages, 0.2);
  EXPECT_NEAR(out.loss.item<double>(), 0.2, 1e-12);
  EXPECT_NEAR(out.clip_fraction.item<double>(), 0.5, 1e-6);
  double kl = 0.0;
  for (double r : {1.0, 1.5, 0.5, 1.1}) kl += (r - 1.0) - std::log(r);
  EXPECT_NEAR(out.approx_kl.item<double>(), kl / 4, 1e-12);
  // Clipped samples pass no gradient; the others -r A / 4.
  out.loss.backward();
  const at::Tensor grad = log_prob.grad();
  EXPECT_NEAR(grad[0].item<double>(), -0.25, 1e-12);
  EXPECT_NEAR(grad[1].item<double>(), 0.0, 1e-12);
  EXPECT_NEAR(grad[2].item<double>(), 0.0, 1e-12);
  EXPECT_NEAR(grad[3].item<double>(), 0.55, 1e-12);
  // Taking the current log-probs as "old" would give ratio 1 and -mean(A).
  const PpoPolicyLoss fresh =
      PpoClippedPolicyLoss(log_prob, log_prob, advantages, 0.2);
  EXPECT_NEAR(fresh.loss.item<double>(), 0.25, 1e-12);
}

}  // namespace
}  // namespace vantage
