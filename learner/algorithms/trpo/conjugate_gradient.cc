#include "learner/algorithms/trpo/conjugate_gradient.h"

#include <ATen/ATen.h>

namespace vantage {

at::Tensor ConjugateGradient(
    absl::FunctionRef<at::Tensor(const at::Tensor&)> product,
    const at::Tensor& b, int iterations, double residual_tolerance) {
  at::Tensor x = at::zeros_like(b);
  at::Tensor r = b.clone();
  at::Tensor p = b.clone();
  double r_dot_r = r.dot(r).item<double>();
  for (int i = 0; i < iterations && r_dot_r >= residual_tolerance; ++i) {
    const at::Tensor ap = product(p);
    const double alpha = r_dot_r / p.dot(ap).item<double>();
    x = x + alpha * p;
    r = r - alpha * ap;
    const double next_r_dot_r = r.dot(r).item<double>();
    p = r + (next_r_dot_r / r_dot_r) * p;
    r_dot_r = next_r_dot_r;
  }
  return x;
}

}  // namespace vantage
