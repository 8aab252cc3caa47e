#include "learner/algorithms/a2c/a2c_updater.h"

#include <ATen/ATen.h>
#include <torch/nn/utils/clip_grad.h>
#include <torch/optim/rmsprop.h>
#include <torch/serialize/input-archive.h>
#include <torch/serialize/output-archive.h>

#include <memory>
#include <random>
#include <sstream>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/algorithms/a2c/tensorflow_rmsprop.h"

namespace vantage {
namespace {

EnvSpec Spec() {
  EnvSpec spec;
  spec.name = "continuous";
  spec.observation_size = 4;
  spec.action_size = 2;
  spec.action_low.assign(2, -1.0);
  spec.action_high.assign(2, 1.0);
  return spec;
}

// The paper's trick: a 5n-step batch is updated as n consecutive 5-step
// minibatches, oldest first, each one RMSProp step on the A2C loss.
// Checked against the same steps written out by hand, with each RMSProp
// arithmetic.
class A2cRmspropTest : public ::testing::TestWithParam<std::string> {};

TEST_P(A2cRmspropTest, UpdatesConsecutiveFiveStepMinibatchesInOrder) {
  constexpr int64_t kStreams = 3;
  constexpr int64_t kHorizon = 15;  // n = 3
  constexpr int64_t kSamples = kHorizon * kStreams;
  NetworkConfig network;
  at::manual_seed(5);
  PolicyNetwork policy(Spec(), network);
  ValueNetwork value(4, network);
  at::manual_seed(5);
  PolicyNetwork reference_policy(Spec(), network);
  ValueNetwork reference_value(4, network);

  UpdateBatch batch;
  batch.horizon = kHorizon;
  batch.streams = kStreams;
  batch.observations = at::randn({kSamples, 4});
  batch.actions = at::randn({kSamples, 2});
  batch.behaviour_log_probs = at::randn({kSamples});
  batch.advantages = at::randn({kSamples});
  batch.returns = at::randn({kSamples});

  A2cConfig config;
  config.n = 3;
  config.rmsprop = GetParam();
  const at::Tensor initial = policy->parameters()[0].clone();
  A2cUpdater a2c(policy, value, config);
  std::mt19937_64 rng(1);
  const double progress = 0.25;
  const AlgorithmStats stats = a2c.Update(batch, progress, rng);

  std::vector<at::Tensor> parameters = reference_policy->parameters();
  for (const at::Tensor& p : reference_value->parameters()) {
    parameters.push_back(p);
  }
  const auto options =
      torch::optim::RMSpropOptions(config.learning_rate * (1 - progress))
          .alpha(0.99)
          .eps(1e-5);
  std::unique_ptr<torch::optim::Optimizer> rmsprop;
  if (GetParam() == "pytorch") {
    rmsprop = std::make_unique<torch::optim::RMSprop>(parameters, options);
  } else {
    rmsprop = std::make_unique<TensorflowRmsprop>(parameters, options);
  }
  double policy_loss = 0.0;
  for (int64_t begin = 0; begin < kSamples; begin += 5 * kStreams) {
    const int64_t end = begin + 5 * kStreams;
    const at::Tensor obs = batch.observations.slice(0, begin, end);
    const at::Tensor out = reference_policy->forward(obs);
    const at::Tensor log_prob =
        reference_policy->LogProb(out, batch.actions.slice(0, begin, end));
    const at::Tensor pg =
        -(log_prob * batch.advantages.slice(0, begin, end)).mean();
    const at::Tensor v =
        reference_value->forward(obs) - batch.returns.slice(0, begin, end);
    const at::Tensor loss = pg + 0.5 * (0.5 * (v * v).mean()) -
                            0.01 * reference_policy->Entropy(out).mean();
    rmsprop->zero_grad();
    loss.backward();
    torch::nn::utils::clip_grad_norm_(parameters, 0.5);
    rmsprop->step();
    policy_loss += pg.item<double>() / 3;
  }
  EXPECT_NEAR(stats.policy_loss, policy_loss, 1e-6);
  const std::vector<at::Tensor> got = policy->parameters();
  const std::vector<at::Tensor> want = reference_policy->parameters();
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_TRUE(at::allclose(got[i], want[i], 1e-5, 1e-6)) << "parameter " << i;
  }
  EXPECT_FALSE(at::allclose(got[0], initial));
}

INSTANTIATE_TEST_SUITE_P(Arithmetics, A2cRmspropTest,
                         ::testing::Values("tensorflow", "pytorch"));

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
