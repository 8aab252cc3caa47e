#include "learner/algorithms/trpo/conjugate_gradient.h"

#include <ATen/ATen.h>

#include "gtest/gtest.h"

namespace vantage {
namespace {

TEST(ConjugateGradientTest, SolvesASymmetricPositiveDefiniteSystem) {
  at::manual_seed(3);
  const at::Tensor m = at::randn({10, 10}, at::kDouble);
  const at::Tensor a = m.matmul(m.t()) + at::eye(10, at::kDouble);
  const at::Tensor b = at::randn({10}, at::kDouble);
  int products = 0;
  const at::Tensor x = ConjugateGradient(
      [&](const at::Tensor& v) {
        ++products;
        return a.mv(v);
      },
      b, /*iterations=*/50);
  EXPECT_TRUE(at::allclose(a.mv(x), b, 1e-8, 1e-8));
  // In exact arithmetic n steps suffice; the tolerance stops it there.
  EXPECT_LE(products, 25);
}

TEST(ConjugateGradientTest, FewIterationsGiveAnApproximation) {
  const at::Tensor a = at::diag(at::tensor({1.0, 10.0, 100.0}, at::kDouble));
  const at::Tensor b = at::ones({3}, at::kDouble);
  const at::Tensor x1 =
      ConjugateGradient([&](const at::Tensor& v) { return a.mv(v); }, b, 1);
  const at::Tensor x3 =
      ConjugateGradient([&](const at::Tensor& v) { return a.mv(v); }, b, 3);
  EXPECT_TRUE(at::allclose(x3, at::tensor({1.0, 0.1, 0.01}, at::kDouble), 1e-10,
                           1e-10));
  EXPECT_GT((a.mv(x1) - b).norm().item<double>(), 1e-3);
}

}  // namespace
}  // namespace vantage
