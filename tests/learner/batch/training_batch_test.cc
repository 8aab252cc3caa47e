#include "learner/batch/training_batch.h"

#include <ATen/ATen.h>

#include <random>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

// A stand-in critic: V(s) = s_0 + 10 s_1, so every value says where it
// came from.
at::Tensor FakeValues(const at::Tensor& observations) {
  return observations.select(1, 0) + 10.0 * observations.select(1, 1);
}

// The critic as AssembleBatch asks for it: each rollout's T + 1
// observations, then every rollout's final observations.
at::Tensor FakeCritic(const std::vector<Rollout>& rollouts) {
  std::vector<at::Tensor> observations, finals;
  for (const Rollout& r : rollouts) {
    observations.push_back(r.observations);
    finals.push_back(r.final_observations);
  }
  return FakeValues(at::cat({at::cat(observations), at::cat(finals)}));
}

Rollout MakeRollout(int64_t steps, int64_t seed) {
  Rollout r;
  r.observations = at::randn({steps + 1, 2});
  r.actions = at::randn({steps, 1});
  r.rewards = at::randn({steps});
  r.terminated = at::zeros({steps}, at::kBool);
  r.truncated = at::zeros({steps}, at::kBool);
  r.terminated[seed % steps] = true;
  r.truncated[(seed + 2) % steps] = true;
  r.truncated[(seed + 4) % steps] = true;
  r.final_observations = at::randn({2, 2});
  r.behaviour_log_probs = at::randn({steps});
  r.policy_versions = at::full({steps}, seed, at::kLong);
  return r;
}

TEST(TrainingBatchTest, EveryValueComesFromTheRightObservation) {
  at::manual_seed(4);
  const std::vector<Rollout> rollouts = {MakeRollout(6, 0), MakeRollout(6, 1),
                                         MakeRollout(6, 3)};
  int calls = 0;
  const absl::StatusOr<TrainingBatch> batch =
      AssembleBatch(rollouts, [&](const std::vector<Rollout>& given) {
        ++calls;
        return FakeCritic(given);
      });
  ASSERT_TRUE(batch.ok()) << batch.status();
  EXPECT_EQ(calls, 1);
  const AdvantageInputs& in = batch->advantage_inputs;
  ASSERT_EQ(in.values.sizes(), at::IntArrayRef({6, 3}));
  EXPECT_TRUE(ValidateAdvantageInputs(in).ok());
  for (int64_t n = 0; n < 3; ++n) {
    const Rollout& r = rollouts[n];
    EXPECT_TRUE(at::allclose(in.values.select(1, n),
                             FakeValues(r.observations.slice(0, 0, 6))));
    EXPECT_NEAR(in.last_values[n].item<float>(),
                FakeValues(r.observations.slice(0, 6, 7))[0].item<float>(),
                1e-6);
    const at::Tensor rows = at::nonzero(r.truncated).reshape({-1});
    const at::Tensor expected = FakeValues(r.final_observations);
    for (int64_t k = 0; k < 2; ++k) {
      EXPECT_NEAR(
          in.truncation_values[rows[k].item<int64_t>()][n].item<float>(),
          expected[k].item<float>(), 1e-6);
    }
    EXPECT_TRUE(at::equal(in.rewards.select(1, n), r.rewards));
    EXPECT_TRUE(at::equal(in.terminated.select(1, n), r.terminated));
    EXPECT_TRUE(at::equal(batch->actions.select(1, n), r.actions));
    EXPECT_TRUE(at::equal(batch->observations.select(1, n),
                          r.observations.slice(0, 0, 6)));
    EXPECT_EQ(batch->policy_versions[0][n].item<int64_t>(),
              r.policy_versions[0].item<int64_t>());
  }
}

TEST(TrainingBatchTest, RefusesMixedLengthsAndEmptyBatches) {
  EXPECT_FALSE(AssembleBatch({}, FakeCritic).ok());
  EXPECT_THAT(AssembleBatch({MakeRollout(6, 0), MakeRollout(5, 0)}, FakeCritic)
                  .status()
                  .message(),
              ::testing::HasSubstr("cannot share a batch"));
}

// Ending returns at the time limits makes every estimate, GAE, the
// path ensemble's statistic and the critic's targets, what it is when the
// truncated steps are terminal ones; bootstrapped, they differ.
TEST(TrainingBatchTest, AReturnEndedAtTheTimeLimitIsOneEndedByTermination) {
  at::manual_seed(5);
  const std::vector<Rollout> rollouts = {MakeRollout(40, 0),
                                         MakeRollout(40, 7)};
  const TrainingBatch bootstrapped = *AssembleBatch(rollouts, FakeCritic);
  AdvantageInputs ended = bootstrapped.advantage_inputs;
  ended.truncation_values = ended.truncation_values.clone();
  EndReturnsAtTimeLimits(ended);
  AdvantageInputs terminal = bootstrapped.advantage_inputs;
  terminal.terminated = at::logical_or(terminal.terminated, terminal.truncated);
  terminal.truncated = at::zeros_like(terminal.truncated);
  terminal.truncation_values = at::zeros_like(terminal.truncation_values);
  AdvantageConfig config;
  config.statistic = *ParseStatistic("max");
  config.ensemble = {1, 4, 16};
  config.rho = 0.5;
  const auto advantages_of = [&](const AdvantageInputs& in) {
    std::mt19937_64 rng(3);
    return *ComputeAdvantages(in, config, rng);
  };
  const Advantages a = advantages_of(ended);
  const Advantages b = advantages_of(terminal);
  EXPECT_TRUE(a.gae.equal(b.gae));
  EXPECT_TRUE(a.biased.equal(b.biased));
  EXPECT_TRUE(a.mixed.equal(b.mixed));
  EXPECT_TRUE(a.returns.equal(b.returns));
  const Advantages c = advantages_of(bootstrapped.advantage_inputs);
  EXPECT_FALSE(c.gae.equal(a.gae));
  EXPECT_FALSE(c.returns.equal(a.returns));
  // A step the limit cut off returns its reward alone.
  const at::Tensor cut = ended.truncated;
  EXPECT_TRUE(at::allclose(a.returns.masked_select(cut),
                           ended.rewards.masked_select(cut)));
}

// With rho = 1 every policy sample uses the biased estimate, and still the
// critic's targets are V + GAE, not V + biased.
TEST(MakeUpdateBatchTest, CriticTargetsStayVPlusGaeAtRhoOne) {
  constexpr int64_t T = 40, N = 3;
  at::manual_seed(2);
  TrainingBatch batch;
  AdvantageInputs& in = batch.advantage_inputs;
  in.rewards = at::randn({T, N});
  in.values = at::randn({T, N});
  in.terminated = at::rand({T, N}) < 0.05;
  in.truncated =
      at::logical_and(at::rand({T, N}) < 0.05, at::logical_not(in.terminated));
  in.truncation_values = at::randn({T, N});
  in.last_values = at::randn({N});
  batch.observations = at::randn({T, N, 2});
  batch.actions = at::randn({T, N, 1});
  batch.behaviour_log_probs = at::randn({T, N});
  AdvantageConfig config;
  config.statistic = *ParseStatistic("max");
  config.ensemble = {1, 4, 16};
  config.rho = 1.0;
  std::mt19937_64 rng(1);
  const Advantages advantages = *ComputeAdvantages(in, config, rng);
  const UpdateBatch update = MakeUpdateBatch(
      batch, advantages, [](const at::Tensor& x) { return x * 2; });
  EXPECT_EQ(update.horizon, T);
  EXPECT_EQ(update.streams, N);
  const at::Tensor gae = *ComputeGae(in, config.gamma, config.lambda);
  const at::Tensor biased = *ComputeBiasedAdvantage(in, config);
  EXPECT_TRUE(update.advantages.equal(biased.reshape({T * N})));
  EXPECT_TRUE(update.returns.equal((in.values + gae).reshape({T * N})));
  EXPECT_FALSE(update.returns.equal((in.values + biased).reshape({T * N})));
  // Time-major rows: row t * N + n is step t of stream n.
  EXPECT_TRUE(
      update.observations[2 * N + 1].equal(batch.observations[2][1] * 2));
  EXPECT_TRUE(update.behaviour_log_probs[2 * N + 1].equal(
      batch.behaviour_log_probs[2][1]));
}

}  // namespace
}  // namespace vantage
