#include "learner/algorithms/ppo/ppo_updater.h"

#include <ATen/ATen.h>
#include <torch/serialize/input-archive.h>
#include <torch/serialize/output-archive.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "tests/fakes/updater_fixtures.h"
#include "tests/fakes/vector_spec.h"

namespace vantage {
namespace {

EnvSpec Spec(bool discrete) {
  return VectorSpec(discrete, 17, discrete ? 5 : 6);
}

PpoConfig SmallConfig() {
  PpoConfig config;
  config.minibatches = 8;
  config.epochs = 4;
  config.max_grad_norm = 0.5;
  return config;
}

void ExpectSameNetworks(Networks& a, Networks& b, double tolerance) {
  ExpectSameParameters(a.parameters(), b.parameters(), tolerance);
}

// Three updates of one batch from the same networks, on the flat path and
// through autograd: the second starts from Adam's state of the first; the
// third takes the batch as one acted by an older version. A recurrent
// policy's batch is chunks of 16 steps from their start states, episodes
// starting inside some.
void ExpectTheFlatUpdateIsTheAutogradUpdate(const EnvSpec& spec,
                                            const NetworkConfig& config) {
  Networks flat_nets = MakeNetworks(spec, 9, config);
  Networks autograd_nets = MakeNetworks(spec, 9, config);
  PpoUpdater flat(flat_nets.policy, flat_nets.value, SmallConfig());
  PpoUpdater autograd(autograd_nets.policy, autograd_nets.value, SmallConfig(),
                      SoloReplicaGroup(),
                      /*autograd_only=*/true);
  ASSERT_TRUE(flat.flat());
  ASSERT_FALSE(autograd.flat());
  at::manual_seed(10);
  UpdateBatch batch =
      config.recurrent()
          ? RecurrentActedBatch(spec, flat_nets, 64, 4, config.seq_len)
          : ActedBatch(spec, flat_nets, 512, 1);
  for (int update = 0; update < 3; ++update) {
    batch.lagged = update == 2;
    std::mt19937_64 rng_a(update), rng_b(update);
    const AlgorithmStats a = flat.Update(batch, 0.25 * update, rng_a);
    const AlgorithmStats b = autograd.Update(batch, 0.25 * update, rng_b);
    ExpectSameNetworks(flat_nets, autograd_nets, 1e-5);
    for (auto [x, y, what] :
         {std::tuple{a.policy_loss, b.policy_loss, "pi"},
          {a.value_loss, b.value_loss, "value"},
          {a.entropy, b.entropy, "entropy"},
          {a.approx_kl, b.approx_kl, "kl"},
          {a.clip_fraction, b.clip_fraction, "clip"},
          {a.max_gradient_norm, b.max_gradient_norm, "norm"}}) {
      EXPECT_NEAR(x, y, 1e-5 * std::max(1.0, std::abs(y))) << what;
    }
    // Some ratios leave the clipping range (against the behaviour policy;
    // the lagged update's start at 1 against the proximal one).
    if (!batch.lagged) EXPECT_GT(a.clip_fraction, 0.0);
  }
}

class PpoUpdaterTest : public ::testing::TestWithParam<bool> {};

TEST_P(PpoUpdaterTest, TheFlatUpdateIsTheAutogradUpdate) {
  ExpectTheFlatUpdateIsTheAutogradUpdate(Spec(GetParam()), NetworkConfig());
}

INSTANTIATE_TEST_SUITE_P(Heads, PpoUpdaterTest, ::testing::Bool());

class RecurrentPpoUpdaterTest : public ::testing::TestWithParam<Core> {};

// A recurrent policy's update through FlatRecurrentCore is the one autograd
// computes through RecurrentTrunkImpl.
TEST_P(RecurrentPpoUpdaterTest, TheFlatUpdateIsTheAutogradUpdate) {
  NetworkConfig config;
  config.core = GetParam();
  config.core_size = 16;
  config.seq_len = 16;
  ExpectTheFlatUpdateIsTheAutogradUpdate(Spec(false), config);
}

INSTANTIATE_TEST_SUITE_P(Cores, RecurrentPpoUpdaterTest,
                         ::testing::Values(Core::kGru, Core::kLstm));

// Every sample's ratio to the behaviour policy is 2, beyond the clipping
// range, and every advantage positive: PPO's clipped surrogate is flat
// there, so a fresh batch leaves the policy as it is (only the critic
// learns), while a lagged one is clipped against the policy as the update
// starts (ratio 1) and moves it.
class DecoupledPpoTest : public ::testing::TestWithParam<bool> {};

TEST_P(DecoupledPpoTest, ALaggedBatchIsClippedAgainstTheProximalPolicy) {
  const bool autograd_only = GetParam();
  const EnvSpec spec = Spec(false);
  PpoConfig config = SmallConfig();
  config.entropy_coef = 0.0;
  config.normalize_advantages = false;
  for (bool lagged : {false, true}) {
    Networks n = MakeNetworks(spec, 13);
    at::manual_seed(14);
    UpdateBatch batch = ActedBatch(spec, n, 256, 1);
    {
      at::NoGradGuard no_grad;
      batch.behaviour_log_probs =
          n.policy->LogProb(n.policy->forward(batch.observations),
                            batch.actions) -
          std::log(2.0);
    }
    batch.advantages = at::ones({256});
    batch.lagged = lagged;
    std::vector<at::Tensor> before;
    for (const at::Tensor& p : n.policy->parameters()) {
      before.push_back(p.detach().clone());
    }
    PpoUpdater updater(n.policy, n.value, config, SoloReplicaGroup(),
                       autograd_only);
    std::mt19937_64 rng(4);
    const AlgorithmStats stats = updater.Update(batch, 0.0, rng);
    double moved = 0.0;
    const std::vector<at::Tensor> after = n.policy->parameters();
    for (size_t i = 0; i < after.size(); ++i) {
      moved =
          std::max(moved, (after[i] - before[i]).abs().max().item<double>());
    }
    if (lagged) {
      EXPECT_GT(moved, 1e-4);
      EXPECT_LT(stats.clip_fraction, 0.5);
    } else {
      EXPECT_EQ(moved, 0.0);
      EXPECT_EQ(stats.clip_fraction, 1.0);
    }
  }
}

// Without lag (the behaviour policy is the proximal one), the decoupled
// objective is PPO's own, bit for bit.
TEST_P(DecoupledPpoTest, WithoutLagItIsPpo) {
  const EnvSpec spec = Spec(false);
  Networks a = MakeNetworks(spec, 15);
  Networks b = MakeNetworks(spec, 15);
  at::manual_seed(16);
  UpdateBatch batch = ActedBatch(spec, a, 256, 1);
  {
    at::NoGradGuard no_grad;
    batch.behaviour_log_probs =
        a.policy->LogProb(a.policy->forward(batch.observations), batch.actions);
  }
  UpdateBatch lagged = batch;
  lagged.lagged = true;
  PpoUpdater fresh(a.policy, a.value, SmallConfig(), SoloReplicaGroup(),
                   GetParam());
  PpoUpdater old(b.policy, b.value, SmallConfig(), SoloReplicaGroup(),
                 GetParam());
  std::mt19937_64 rng_a(5), rng_b(5);
  fresh.Update(batch, 0.0, rng_a);
  old.Update(lagged, 0.0, rng_b);
  ExpectSameNetworks(a, b, 0.0);
}

INSTANTIATE_TEST_SUITE_P(Paths, DecoupledPpoTest, ::testing::Bool());

TEST(PpoUpdaterStateTest, CheckpointsResumeExactlyAndCrossBetweenPaths) {
  const EnvSpec spec = Spec(false);
  Networks first = MakeNetworks(spec, 11);
  Networks second = MakeNetworks(spec, 11);
  PpoUpdater a(first.policy, first.value, SmallConfig());
  at::manual_seed(12);
  const UpdateBatch batch = ActedBatch(spec, first, 256, 1);
  std::mt19937_64 rng(1);
  a.Update(batch, 0.0, rng);
  const std::string state = Saved(a);
  // The networks as the first update left them, and its optimiser state.
  {
    at::NoGradGuard no_grad;
    const std::vector<at::Tensor> from =
        NetworkParameters(*first.policy, *first.value);
    const std::vector<at::Tensor> to =
        NetworkParameters(*second.policy, *second.value);
    for (size_t i = 0; i < from.size(); ++i) to[i].copy_(from[i]);
  }
  PpoUpdater b(second.policy, second.value, SmallConfig());
  ASSERT_TRUE(LoadInto(b, state).ok());
  std::mt19937_64 rng_a(2), rng_b(2);
  a.Update(batch, 0.1, rng_a);
  b.Update(batch, 0.1, rng_b);
  ExpectSameNetworks(first, second, 0.0);

  // The same state read by the autograd path continues alike.
  Networks third = MakeNetworks(spec, 11);
  {
    at::NoGradGuard no_grad;
    const std::vector<at::Tensor> from =
        NetworkParameters(*first.policy, *first.value);
    const std::vector<at::Tensor> to =
        NetworkParameters(*third.policy, *third.value);
    for (size_t i = 0; i < from.size(); ++i) to[i].copy_(from[i]);
  }
  PpoUpdater c(third.policy, third.value, SmallConfig(), SoloReplicaGroup(),
               /*autograd_only=*/true);
  ASSERT_TRUE(LoadInto(c, Saved(a)).ok());
  std::mt19937_64 rng_c(3), rng_d(3);
  a.Update(batch, 0.2, rng_c);
  c.Update(batch, 0.2, rng_d);
  ExpectSameNetworks(first, third, 1e-5);
}

}  // namespace
}  // namespace vantage
