#ifndef VANTAGE_LEARNER_ALGORITHMS_TRPO_CONJUGATE_GRADIENT_H_
#define VANTAGE_LEARNER_ALGORITHMS_TRPO_CONJUGATE_GRADIENT_H_

#include <ATen/core/Tensor.h>

#include "absl/functional/function_ref.h"

namespace vantage {

// Solves A x = b for a symmetric positive definite A known only through
// products v -> A v (TRPO's Fisher-vector product), starting from x = 0.
// Stops after `iterations` steps or once |r|^2 < residual_tolerance.
at::Tensor ConjugateGradient(
    absl::FunctionRef<at::Tensor(const at::Tensor&)> product,
    const at::Tensor& b, int iterations, double residual_tolerance = 1e-10);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_TRPO_CONJUGATE_GRADIENT_H_
