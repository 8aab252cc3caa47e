#include "learner/algorithms/a2c/a2c_updater.h"

#include <ATen/ATen.h>
#include <torch/nn/utils/clip_grad.h>
#include <torch/optim/rmsprop.h>
#include <torch/serialize/input-archive.h>
#include <torch/serialize/output-archive.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/algorithms/a2c/tensorflow_rmsprop.h"
#include "tests/fakes/updater_fixtures.h"
#include "tests/fakes/vector_spec.h"

namespace vantage {
namespace {

EnvSpec Spec() { return VectorSpec(false, 4, 2); }

std::unique_ptr<torch::optim::Optimizer> ReferenceRmsprop(
    const std::vector<at::Tensor>& parameters, const std::string& arithmetic) {
  const auto options = torch::optim::RMSpropOptions(7e-4).alpha(0.99).eps(1e-5);
  if (arithmetic == "pytorch") {
    return std::make_unique<torch::optim::RMSprop>(parameters, options);
  }
  return std::make_unique<TensorflowRmsprop>(parameters, options);
}

// The paper's trick: a 5n-step batch is updated as n consecutive 5-step
// minibatches, oldest first, each one RMSProp step on the A2C loss.
// Checked against the same steps written out by hand on autograd, for each
// RMSProp arithmetic, head, and update path (flat or autograd), over two
// updates (the second from the optimiser's state after the first).
class A2cRmspropTest
    : public ::testing::TestWithParam<std::tuple<std::string, bool, bool>> {};

TEST_P(A2cRmspropTest, UpdatesConsecutiveFiveStepMinibatchesInOrder) {
  const auto& [arithmetic, discrete, autograd_only] = GetParam();
  constexpr int64_t kStreams = 3;
  constexpr int64_t kHorizon = 15;  // n = 3
  const EnvSpec spec = VectorSpec(discrete, 4, discrete ? 3 : 2);
  Networks nets = MakeNetworks(spec, 5);
  Networks reference = MakeNetworks(spec, 5);
  at::manual_seed(6);
  const UpdateBatch batch = ActedBatch(spec, nets, kHorizon, kStreams);

  A2cConfig config;
  config.n = 3;
  config.rmsprop = arithmetic;
  const at::Tensor initial = nets.policy->parameters()[0].clone();
  A2cUpdater a2c(nets.policy, nets.value, config, SoloReplicaGroup(),
                 autograd_only);
  EXPECT_EQ(a2c.flat(), !autograd_only);

  std::vector<at::Tensor> parameters = reference.parameters();
  std::unique_ptr<torch::optim::Optimizer> rmsprop =
      ReferenceRmsprop(parameters, arithmetic);
  for (const double progress : {0.25, 0.5}) {
    std::mt19937_64 rng(1);
    const AlgorithmStats stats = a2c.Update(batch, progress, rng);
    for (auto& group : rmsprop->param_groups()) {
      group.options().set_lr(config.learning_rate * (1 - progress));
    }
    double policy_loss = 0.0, value_loss = 0.0, entropy = 0.0, norm = 0.0;
    for (int64_t begin = 0; begin < kHorizon * kStreams;
         begin += 5 * kStreams) {
      const int64_t end = begin + 5 * kStreams;
      const at::Tensor obs = batch.observations.slice(0, begin, end);
      const at::Tensor out = reference.policy->forward(obs);
      const at::Tensor log_prob =
          reference.policy->LogProb(out, batch.actions.slice(0, begin, end));
      const at::Tensor pg =
          -(log_prob * batch.advantages.slice(0, begin, end)).mean();
      const at::Tensor v =
          reference.value->forward(obs) - batch.returns.slice(0, begin, end);
      const at::Tensor vf = 0.5 * (v * v).mean();
      const at::Tensor h = reference.policy->Entropy(out).mean();
      const at::Tensor loss = pg + 0.5 * vf - 0.01 * h;
      rmsprop->zero_grad();
      loss.backward();
      norm = std::max(norm, torch::nn::utils::clip_grad_norm_(parameters, 0.5));
      rmsprop->step();
      policy_loss += pg.item<double>() / 3;
      value_loss += vf.item<double>() / 3;
      entropy += h.item<double>() / 3;
    }
    for (auto [got, want, what] :
         {std::tuple{stats.policy_loss, policy_loss, "pi"},
          {stats.value_loss, value_loss, "value"},
          {stats.entropy, entropy, "entropy"},
          {stats.max_gradient_norm, norm, "norm"}}) {
      EXPECT_NEAR(got, want, 1e-5 * std::max(1.0, std::abs(want))) << what;
    }
    EXPECT_GT(stats.approx_kl, 0.0);
    EXPECT_TRUE(std::isnan(stats.clip_fraction));
    ExpectSameParameters(nets.parameters(), reference.parameters(), 1e-5);
  }
  EXPECT_FALSE(at::allclose(nets.policy->parameters()[0], initial));
}

INSTANTIATE_TEST_SUITE_P(
    ArithmeticsHeadsAndPaths, A2cRmspropTest,
    ::testing::Combine(::testing::Values("tensorflow", "pytorch"),
                       ::testing::Bool(), ::testing::Bool()));

// A checkpoint of the flat path resumes on autograd and the other way
// round: the next update is the same either way.
TEST(A2cTest, CheckpointsCrossBetweenTheFlatAndAutogradPaths) {
  for (const std::string arithmetic : {"tensorflow", "pytorch"}) {
    const EnvSpec spec = Spec();
    A2cConfig config;
    config.rmsprop = arithmetic;
    Networks a = MakeNetworks(spec, 7);
    at::manual_seed(8);
    const UpdateBatch batch = ActedBatch(spec, a, config.horizon(), 2);
    A2cUpdater flat(a.policy, a.value, config);
    std::mt19937_64 rng(0);
    flat.Update(batch, 0.1, rng);
    const std::string after_one = Saved(flat);

    Networks b = MakeNetworks(spec, 7);
    for (size_t i = 0; i < b.parameters().size(); ++i) {
      at::NoGradGuard no_grad;
      b.parameters()[i].copy_(a.parameters()[i]);
    }
    A2cUpdater autograd(b.policy, b.value, config, SoloReplicaGroup(),
                        /*autograd_only=*/true);
    ASSERT_TRUE(LoadInto(autograd, after_one).ok());
    flat.Update(batch, 0.2, rng);
    autograd.Update(batch, 0.2, rng);
    ExpectSameParameters(a.parameters(), b.parameters(), 1e-5);

    // And back: the autograd path's state into a fresh flat updater.
    Networks c = MakeNetworks(spec, 7);
    for (size_t i = 0; i < c.parameters().size(); ++i) {
      at::NoGradGuard no_grad;
      c.parameters()[i].copy_(b.parameters()[i]);
    }
    A2cUpdater resumed(c.policy, c.value, config);
    ASSERT_TRUE(LoadInto(resumed, Saved(autograd)).ok());
    autograd.Update(batch, 0.3, rng);
    resumed.Update(batch, 0.3, rng);
    ExpectSameParameters(c.parameters(), b.parameters(), 1e-5);
  }
}

// Both arithmetics keep the same state; the checkpoint says which one made
// it, so a run cannot continue under the other.
TEST(A2cTest, ACheckpointNamesItsRmspropArithmetic) {
  NetworkConfig network;
  A2cConfig config;
  config.rmsprop = "tensorflow";
  A2cUpdater tensorflow(PolicyNetwork(Spec(), network),
                        ValueNetwork(4, network), config);
  torch::serialize::OutputArchive out;
  tensorflow.Save(out);
  std::ostringstream bytes;
  out.save_to(bytes);
  const auto load_into = [&](const std::string& arithmetic) {
    A2cConfig other = config;
    other.rmsprop = arithmetic;
    A2cUpdater updater(PolicyNetwork(Spec(), network), ValueNetwork(4, network),
                       other);
    std::istringstream in_bytes(bytes.str());
    torch::serialize::InputArchive in;
    in.load_from(in_bytes);
    return updater.Load(in);
  };
  EXPECT_TRUE(load_into("tensorflow").ok());
  const absl::Status status = load_into("pytorch");
  EXPECT_THAT(std::string(status.message()),
              ::testing::HasSubstr("optimiser state 'rmsprop'"));
}

TEST(A2cConfigTest, ValidatesItsSettings) {
  A2cConfig config;
  EXPECT_TRUE(config.Validate().ok());
  EXPECT_EQ(config.horizon(), 20);
  config.n = 1;  // the original A2C
  EXPECT_EQ(config.horizon(), 5);
  config.n = 20;
  EXPECT_EQ(config.horizon(), 100);
  config.n = 0;
  EXPECT_EQ(config.Validate().message(), "a2c.n must be >= 1");
  config = A2cConfig();
  config.rmsprop_alpha = 1.0;
  EXPECT_EQ(config.Validate().message(), "a2c.rmsprop_alpha must be in (0, 1)");
  config = A2cConfig();
  config.rmsprop_eps = 0;
  EXPECT_EQ(config.Validate().message(), "a2c.rmsprop_eps must be > 0");
  config = A2cConfig();
  config.rmsprop = "adam";
  EXPECT_EQ(config.Validate().message(),
            "a2c.rmsprop must be tensorflow or pytorch, not 'adam'");
}

}  // namespace
}  // namespace vantage
