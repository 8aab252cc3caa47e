#include "learner/algorithms/trpo/trpo_updater.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <random>

#include "gtest/gtest.h"

namespace vantage {
namespace {

EnvSpec Spec(bool discrete) {
  EnvSpec spec;
  spec.name = discrete ? "discrete" : "continuous";
  spec.observation_size = 5;
  spec.discrete = discrete;
  spec.action_size = discrete ? 4 : 3;
  if (!discrete) {
    spec.action_low.assign(3, -1.0);
    spec.action_high.assign(3, 1.0);
  }
  return spec;
}

// On-policy data whose advantages reward the first action component (or
// action 0), so the surrogate has a clear direction to improve in.
UpdateBatch MakeBatch(PolicyNetworkImpl& policy, int64_t size) {
  at::NoGradGuard no_grad;
  UpdateBatch batch;
  batch.horizon = size;
  batch.streams = 1;
  batch.observations = at::randn({size, 5});
  const at::Tensor output = policy.forward(batch.observations);
  batch.actions = policy.Act(output, /*deterministic=*/false, at::Generator());
  batch.behaviour_log_probs = policy.LogProb(output, batch.actions);
  batch.advantages = policy.discrete()
                         ? (batch.actions.squeeze(1) == 0).to(at::kFloat)
                         : batch.actions.select(1, 0);
  batch.returns = at::randn({size});
  return batch;
}

double MeanKl(PolicyNetworkImpl& policy, const at::Tensor& old_output,
              const at::Tensor& old_log_std, const at::Tensor& observations) {
  at::NoGradGuard no_grad;
  return policy.Kl(old_output, old_log_std, policy.forward(observations))
      .mean()
      .item<double>();
}

class TrpoTest : public ::testing::TestWithParam<std::tuple<bool, double>> {};

// The accepted step stays inside the trust region, reaches a good part of
// it (the step is scaled to its edge and halved at most a few times), and
// improves the surrogate; the reported KL is the step's.
TEST_P(TrpoTest, StepRespectsMaxKlAndImproves) {
  const auto [discrete, max_kl] = GetParam();
  at::manual_seed(11);
  NetworkConfig network;
  PolicyNetwork policy(Spec(discrete), network);
  ValueNetwork value(5, network);
  const UpdateBatch batch = MakeBatch(*policy, 512);
  at::Tensor old_output, old_log_std;
  {
    at::NoGradGuard no_grad;
    old_output = policy->forward(batch.observations);
    if (!discrete) old_log_std = policy->log_std().clone();
  }
  TrpoConfig config;
  config.max_kl = max_kl;
  TrpoUpdater trpo(policy, value, config);
  std::mt19937_64 rng(1);
  const AlgorithmStats stats = trpo.Update(batch, 0.0, rng);
  const double kl =
      MeanKl(*policy, old_output, old_log_std, batch.observations);
  EXPECT_LE(kl, max_kl);
  EXPECT_GT(kl, max_kl / 16);
  EXPECT_NEAR(stats.approx_kl, kl, 1e-6 * max_kl + 1e-9);
  // The surrogate of normalised advantages starts at mean(A) = 0.
  EXPECT_LT(stats.policy_loss, 0.0);
  EXPECT_TRUE(std::isnan(stats.clip_fraction));
}

INSTANTIATE_TEST_SUITE_P(Policies, TrpoTest,
                         ::testing::Combine(::testing::Bool(),
                                            ::testing::Values(0.01, 1e-4)));

// With nothing to gain the line search accepts no step: the policy stays.
TEST(TrpoStillTest, ZeroAdvantagesLeaveThePolicyUnchanged) {
  at::manual_seed(12);
  NetworkConfig network;
  PolicyNetwork policy(Spec(false), network);
  ValueNetwork value(5, network);
  UpdateBatch batch = MakeBatch(*policy, 128);
  batch.advantages = at::zeros({128});
  std::vector<at::Tensor> before;
  for (const at::Tensor& p : policy->parameters()) before.push_back(p.clone());
  TrpoUpdater trpo(policy, value, TrpoConfig());
  std::mt19937_64 rng(1);
  const AlgorithmStats stats = trpo.Update(batch, 0.0, rng);
  EXPECT_EQ(stats.approx_kl, 0.0);
  const std::vector<at::Tensor> after = policy->parameters();
  for (size_t i = 0; i < before.size(); ++i) {
    EXPECT_TRUE(before[i].equal(after[i])) << "parameter " << i;
  }
}

// The value function is fitted: its loss on the batch's targets falls.
TEST(TrpoValueTest, FitsTheValueFunction) {
  at::manual_seed(13);
  NetworkConfig network;
  PolicyNetwork policy(Spec(false), network);
  ValueNetwork value(5, network);
  UpdateBatch batch = MakeBatch(*policy, 512);
  batch.returns = batch.observations.select(1, 0) * 3 + 1;
  auto loss = [&] {
    at::NoGradGuard no_grad;
    const at::Tensor e = value->forward(batch.observations) - batch.returns;
    return (e * e).mean().item<double>();
  };
  const double before = loss();
  TrpoUpdater trpo(policy, value, TrpoConfig());
  std::mt19937_64 rng(1);
  trpo.Update(batch, 0.0, rng);
  EXPECT_LT(loss(), 0.5 * before);
}

}  // namespace
}  // namespace vantage
