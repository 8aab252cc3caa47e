#include "common/nn/networks.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>

#include <cmath>

#include "common/nn/distributions.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

EnvSpec ContinuousSpec() {
  EnvSpec spec;
  spec.name = "test";
  spec.observation_size = 5;
  spec.action_size = 3;
  spec.action_low.assign(3, -1.0);
  spec.action_high.assign(3, 1.0);
  return spec;
}

TEST(NetworksTest, OrthogonalInitialisationWithTheBaselinesGains) {
  at::manual_seed(0);
  PolicyNetwork policy(ContinuousSpec(), NetworkConfig{{64, 64}});
  const auto parameters = policy->named_parameters();
  // First hidden layer [64, 5]: orthonormal columns scaled by sqrt(2).
  const at::Tensor w0 = parameters["body.layers.0.weight"];
  EXPECT_TRUE(at::allclose(w0.t().matmul(w0), 2.0 * at::eye(5), 1e-4, 1e-4));
  // Output layer [3, 64]: orthonormal rows scaled by 0.01.
  const at::Tensor w2 = parameters["body.layers.2.weight"];
  EXPECT_TRUE(at::allclose(w2.matmul(w2.t()), 1e-4 * at::eye(3), 1e-7, 1e-7));
  EXPECT_EQ(parameters["body.layers.0.bias"].abs().sum().item<float>(), 0.0f);
  EXPECT_TRUE(at::equal(policy->log_std(), at::zeros({3})));
  ValueNetwork value(5, NetworkConfig{{64, 64}});
  const at::Tensor v2 = value->named_parameters()["body.layers.2.weight"];
  EXPECT_NEAR(v2.norm().item<float>(), 1.0f, 1e-4);
}

TEST(NetworksTest, GaussianPolicyLogProbEntropyAndSampling) {
  at::manual_seed(1);
  PolicyNetwork policy(ContinuousSpec(), NetworkConfig{{16}});
  const at::Tensor observations = at::randn({4, 5});
  const at::Tensor mean = policy->forward(observations);
  ASSERT_EQ(mean.sizes(), at::IntArrayRef({4, 3}));
  const at::Tensor actions = at::randn({4, 3});
  EXPECT_TRUE(
      at::allclose(policy->LogProb(mean, actions),
                   DiagGaussianLogProb(mean, policy->log_std(), actions)));
  EXPECT_TRUE(at::allclose(policy->Entropy(mean),
                           at::full({4}, 3 * 0.5 * std::log(2 * M_PI * M_E))));
  at::Generator a = at::make_generator<at::CPUGeneratorImpl>(7);
  at::Generator b = at::make_generator<at::CPUGeneratorImpl>(7);
  const at::Tensor first = policy->Act(mean, false, a);
  EXPECT_TRUE(at::equal(first, policy->Act(mean, false, b)));
  EXPECT_FALSE(at::equal(first, mean));
  EXPECT_TRUE(at::equal(policy->Act(mean, true, a), mean));
  // Gradients reach the log-std.
  policy->LogProb(mean, actions).sum().backward();
  EXPECT_TRUE(policy->log_std().grad().defined());
}

TEST(NetworksTest, CategoricalPolicy) {
  EnvSpec spec;
  spec.name = "discrete";
  spec.observation_size = 2;
  spec.discrete = true;
  spec.action_size = 4;
  PolicyNetwork policy(spec, NetworkConfig{{8}});
  EXPECT_FALSE(policy->log_std().defined());
  const at::Tensor logits = policy->forward(at::randn({6, 2}));
  ASSERT_EQ(logits.sizes(), at::IntArrayRef({6, 4}));
  at::Generator g = at::make_generator<at::CPUGeneratorImpl>(3);
  const at::Tensor actions = policy->Act(logits, false, g);
  ASSERT_EQ(actions.sizes(), at::IntArrayRef({6, 1}));
  EXPECT_TRUE(((actions >= 0) & (actions < 4)).all().item<bool>());
  EXPECT_TRUE(at::allclose(policy->LogProb(logits, actions),
                           CategoricalLogProb(logits, actions.reshape({-1}))));
  // The near-zero initial logits make the policy almost uniform.
  EXPECT_NEAR(policy->Entropy(logits).mean().item<float>(), std::log(4.0),
              1e-3);
}

TEST(NetworksTest, ValueNetworkShape) {
  ValueNetwork value(5, NetworkConfig{});
  EXPECT_EQ(value->forward(at::randn({7, 5})).sizes(), at::IntArrayRef({7}));
}

}  // namespace
}  // namespace vantage
