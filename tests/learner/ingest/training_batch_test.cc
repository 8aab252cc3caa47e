#include "learner/ingest/training_batch.h"

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
      AssembleBatch(rollouts, [&](const at::Tensor& observations) {
        ++calls;
        return FakeValues(observations);
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
  EXPECT_FALSE(AssembleBatch({}, FakeValues).ok());
  EXPECT_THAT(AssembleBatch({MakeRollout(6, 0), MakeRollout(5, 0)}, FakeValues)
                  .status()
                  .message(),
              ::testing::HasSubstr("cannot share a batch"));
}

}  // namespace
}  // namespace vantage
