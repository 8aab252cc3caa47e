#ifndef VANTAGE_LEARNER_ALGORITHMS_FLAT_OPTIMIZER_KERNELS_H_
#define VANTAGE_LEARNER_ALGORITHMS_FLAT_OPTIMIZER_KERNELS_H_

// The element-wise passes of the flat optimisers (FlatAdam, FlatRmsprop)
// over flat float arrays. Their source is compiled without errno for the
// square root, so that the compiler vectorises the loops, and without
// floating-point contraction: every element is rounded exactly as the
// plain scalar loop rounds it, on every CPU.

#include <cstdint>

namespace vantage {

// One Adam step's scalars, in float as LibTorch's float kernels take them.
struct AdamCoefficients {
  float beta1 = 0.0f;
  float beta2 = 0.0f;
  float one_minus_beta1 = 0.0f;
  float one_minus_beta2 = 0.0f;
  float correction2_sqrt = 1.0f;  // sqrt(1 - beta2^step)
  float eps = 0.0f;
  float step_size = 0.0f;  // lr / (1 - beta1^step)
};

// m = beta1 m + (1 - beta1) g; v = beta2 v + (1 - beta2) g^2;
// p -= step_size * m / (sqrt(v) / correction2_sqrt + eps).
void AdamKernel(AdamCoefficients c, int64_t size, float* parameters,
                const float* gradients, float* exp_avg, float* exp_avg_sq);

// RMSProp's square average and step, in LibTorch's order (v = alpha v +
// (1 - alpha) g^2; p += (-lr g) / root) with root = sqrt(v) + eps
// (LibTorch) or, `eps_inside` (TensorFlow's RMSProp), sqrt(v + eps).
void RmspropKernel(float alpha, float one_minus_alpha, float eps,
                   float minus_lr, bool eps_inside, int64_t size,
                   float* parameters, const float* gradients,
                   float* square_avg);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_FLAT_OPTIMIZER_KERNELS_H_
