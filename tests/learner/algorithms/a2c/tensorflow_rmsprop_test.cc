#include "learner/algorithms/a2c/tensorflow_rmsprop.h"

#include <ATen/ATen.h>
#include <torch/serialize/input-archive.h>
#include <torch/serialize/output-archive.h>

#include <cmath>
#include <sstream>
#include <vector>

#include "gtest/gtest.h"

namespace vantage {
namespace {

// TensorFlow's ApplyRMSProp written out in double precision, one
// coordinate at a time: ms starts at 1 and eps sits inside the root.
struct ReferenceRmsprop {
  double lr, alpha, eps;
  std::vector<double> ms;
  void Step(std::vector<double>& p, const std::vector<double>& g) {
    if (ms.empty()) ms.assign(p.size(), 1.0);
    for (size_t i = 0; i < p.size(); ++i) {
      ms[i] = alpha * ms[i] + (1 - alpha) * g[i] * g[i];
      p[i] -= lr * g[i] / std::sqrt(ms[i] + eps);
    }
  }
};

std::vector<double> Values(const at::Tensor& t) {
  const at::Tensor d = t.to(at::kDouble).contiguous();
  return std::vector<double>(d.data_ptr<double>(),
                             d.data_ptr<double>() + d.numel());
}

TEST(TensorflowRmspropTest, StepsAsTensorflowComputesThem) {
  at::manual_seed(3);
  // Gradients from tiny to large, where the two arithmetics differ most.
  at::Tensor p = at::randn({6}, at::kDouble).requires_grad_(true);
  std::vector<double> want = Values(p);
  const auto options = torch::optim::RMSpropOptions(7e-4).alpha(0.99).eps(1e-5);
  TensorflowRmsprop optimizer({p}, options);
  ReferenceRmsprop reference{7e-4, 0.99, 1e-5, {}};
  const at::Tensor scale =
      at::tensor({1e-6, 1e-3, 0.1, 1.0, 10.0, 100.0}, at::kDouble);
  for (int t = 0; t < 5; ++t) {
    const at::Tensor g = at::randn({6}, at::kDouble) * scale;
    p.mutable_grad() = g.clone();
    optimizer.step();
    reference.Step(want, Values(g));
    const std::vector<double> got = Values(p.detach());
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_NEAR(got[i], want[i], 1e-12) << "step " << t << " coord " << i;
    }
  }
  // The first step of a coordinate with gradient g is lr g / sqrt(alpha +
  // (1 - alpha) g^2 + eps), about lr g, where torch's RMSprop moves by about
  // 10 lr sign(g) whatever g's size.
  at::Tensor q = at::zeros({1}, at::kDouble).requires_grad_(true);
  TensorflowRmsprop first({q}, options);
  q.mutable_grad() = at::full({1}, 1e-3, at::kDouble);
  first.step();
  EXPECT_NEAR(q.item<double>(), -7e-4 * 1e-3 / std::sqrt(0.99 + 1e-8 + 1e-5),
              1e-15);
}

TEST(TensorflowRmspropTest, ASavedStateContinuesExactly) {
  at::manual_seed(4);
  const auto options = torch::optim::RMSpropOptions(1e-2).alpha(0.9).eps(1e-5);
  at::Tensor a = at::randn({3, 2}).requires_grad_(true);
  at::Tensor b = a.detach().clone().requires_grad_(true);
  TensorflowRmsprop first({a}, options);
  TensorflowRmsprop second({b}, options);
  const std::vector<at::Tensor> grads = {at::randn({3, 2}), at::randn({3, 2}),
                                         at::randn({3, 2})};
  a.mutable_grad() = grads[0].clone();
  first.step();
  torch::serialize::OutputArchive out;
  first.save(out);
  std::ostringstream bytes;
  out.save_to(bytes);
  {
    at::NoGradGuard no_grad;
    b.copy_(a);
  }
  std::istringstream in_bytes(bytes.str());
  torch::serialize::InputArchive in;
  in.load_from(in_bytes);
  second.load(in);
  for (size_t t = 1; t < grads.size(); ++t) {
    a.mutable_grad() = grads[t].clone();
    b.mutable_grad() = grads[t].clone();
    first.step();
    second.step();
  }
  EXPECT_TRUE(at::equal(a, b));
  // Without the saved mean square, the same gradients move it elsewhere.
  at::Tensor c = at::zeros({3, 2}).requires_grad_(true);
  {
    at::NoGradGuard no_grad;
    c.copy_(b);
  }
  TensorflowRmsprop fresh({c}, options);
  c.mutable_grad() = grads[2].clone();
  fresh.step();
  b.mutable_grad() = grads[2].clone();
  second.step();
  EXPECT_FALSE(at::allclose(b, c));
}

}  // namespace
}  // namespace vantage
