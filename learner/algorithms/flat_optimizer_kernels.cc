#include "learner/algorithms/flat_optimizer_kernels.h"

#include <cmath>

namespace vantage {

void AdamKernel(AdamCoefficients c, int64_t size, float* parameters,
                const float* gradients, float* exp_avg, float* exp_avg_sq) {
  for (int64_t i = 0; i < size; ++i) {
    const float g = gradients[i];
    const float m = exp_avg[i] * c.beta1 + c.one_minus_beta1 * g;
    const float v = exp_avg_sq[i] * c.beta2 + c.one_minus_beta2 * g * g;
    exp_avg[i] = m;
    exp_avg_sq[i] = v;
    const float denominator = std::sqrt(v) / c.correction2_sqrt + c.eps;
    parameters[i] -= c.step_size * (m / denominator);
  }
}

void RmspropKernel(float alpha, float one_minus_alpha, float eps,
                   float minus_lr, bool eps_inside, int64_t size,
                   float* parameters, const float* gradients,
                   float* square_avg) {
  if (eps_inside) {
    for (int64_t i = 0; i < size; ++i) {
      const float g = gradients[i];
      const float v = square_avg[i] * alpha + one_minus_alpha * g * g;
      square_avg[i] = v;
      parameters[i] += minus_lr * g / std::sqrt(v + eps);
    }
    return;
  }
  for (int64_t i = 0; i < size; ++i) {
    const float g = gradients[i];
    const float v = square_avg[i] * alpha + one_minus_alpha * g * g;
    square_avg[i] = v;
    parameters[i] += minus_lr * g / (std::sqrt(v) + eps);
  }
}

}  // namespace vantage
