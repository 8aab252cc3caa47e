#include "common/nn/distributions.h"

#include <ATen/ATen.h>

#include <cmath>

#include "gtest/gtest.h"

namespace vantage {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(DiagGaussianTest, LogProbMatchesTheClosedForm) {
  at::manual_seed(0);
  const at::Tensor mean = at::randn({5, 3}, at::kDouble);
  const at::Tensor log_std = at::randn({3}, at::kDouble) * 0.5;
  const at::Tensor actions = at::randn({5, 3}, at::kDouble);
  const at::Tensor log_prob = DiagGaussianLogProb(mean, log_std, actions);
  ASSERT_EQ(log_prob.sizes(), at::IntArrayRef({5}));
  for (int b = 0; b < 5; ++b) {
    double expected = 0.0;
    for (int j = 0; j < 3; ++j) {
      const double sigma = std::exp(log_std[j].item<double>());
      const double z =
          (actions[b][j].item<double>() - mean[b][j].item<double>()) / sigma;
      expected += -0.5 * z * z - std::log(sigma) - 0.5 * std::log(2 * kPi);
    }
    EXPECT_NEAR(log_prob[b].item<double>(), expected, 1e-12);
  }
  // The standard normal at its mean.
  EXPECT_NEAR(DiagGaussianLogProb(at::zeros({1, 1}, at::kDouble),
                                  at::zeros({1}, at::kDouble),
                                  at::zeros({1, 1}, at::kDouble))
                  .item<double>(),
              -0.5 * std::log(2 * kPi), 1e-12);
}

TEST(DiagGaussianTest, EntropyAndKlMatchTheClosedForms) {
  const at::Tensor mean = at::zeros({2, 3}, at::kDouble);
  const at::Tensor log_std =
      at::tensor({0.0, std::log(2.0), -1.0}, at::kDouble);
  const at::Tensor entropy = DiagGaussianEntropy(mean, log_std);
  const double expected =
      3 * 0.5 * std::log(2 * kPi * std::exp(1.0)) + std::log(2.0) - 1.0;
  EXPECT_NEAR(entropy[0].item<double>(), expected, 1e-12);
  EXPECT_NEAR(entropy[1].item<double>(), expected, 1e-12);
  // KL(N(0, 1) || N(1, 2^2)) = log 2 + (1 + 1) / 8 - 1/2.
  const at::Tensor kl = DiagGaussianKl(
      at::zeros({1, 1}, at::kDouble), at::zeros({1}, at::kDouble),
      at::ones({1, 1}, at::kDouble), at::full({1}, std::log(2.0), at::kDouble));
  EXPECT_NEAR(kl.item<double>(), std::log(2.0) + 0.25 - 0.5, 1e-12);
  EXPECT_NEAR(
      DiagGaussianKl(mean, log_std, mean, log_std).abs().max().item<double>(),
      0.0, 1e-12);
}

TEST(DiagGaussianTest, GradientOfTheLogProbIsTheScore) {
  const at::Tensor mean =
      at::tensor({0.5}, at::kDouble).reshape({1, 1}).set_requires_grad(true);
  const at::Tensor log_std = at::full({1}, std::log(2.0), at::kDouble);
  const at::Tensor action = at::tensor({1.5}, at::kDouble).reshape({1, 1});
  DiagGaussianLogProb(mean, log_std, action).sum().backward();
  // d/dmu log N(a; mu, s^2) = (a - mu) / s^2 = 1 / 4.
  EXPECT_NEAR(mean.grad().item<double>(), 0.25, 1e-12);
}

TEST(CategoricalTest, LogProbEntropyAndKlMatchTheClosedForms) {
  const at::Tensor logits =
      at::log(at::tensor({0.2, 0.3, 0.5}, at::kDouble)).reshape({1, 3}) + 7.0;
  const at::Tensor actions = at::tensor({2}, at::kLong);
  EXPECT_NEAR(CategoricalLogProb(logits, actions).item<double>(), std::log(0.5),
              1e-12);
  const double entropy =
      -(0.2 * std::log(0.2) + 0.3 * std::log(0.3) + 0.5 * std::log(0.5));
  EXPECT_NEAR(CategoricalEntropy(logits).item<double>(), entropy, 1e-12);
  // KL(p || uniform) = log 3 - H(p).
  const at::Tensor uniform = at::zeros({1, 3}, at::kDouble);
  EXPECT_NEAR(CategoricalKl(logits, uniform).item<double>(),
              std::log(3.0) - entropy, 1e-12);
}

}  // namespace
}  // namespace vantage
