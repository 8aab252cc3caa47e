#ifndef VANTAGE_COMMON_NN_DISTRIBUTIONS_H_
#define VANTAGE_COMMON_NN_DISTRIBUTIONS_H_

// The policy distributions' densities, entropies and KL divergences as
// differentiable tensor functions, per sample ([B]).

#include <ATen/core/Tensor.h>

#include <cstdint>

namespace vantage {

// log(sqrt(2 pi)), the Gaussian's normalising term per dimension.
constexpr double kLogSqrtTwoPi = 0.91893853320467274178;

// Diagonal Gaussian N(mean, exp(log_std)^2): mean and actions [B, k];
// log_std [k] (state-independent) or [B, k]. Sums over the k dimensions.
at::Tensor DiagGaussianLogProb(const at::Tensor& mean,
                               const at::Tensor& log_std,
                               const at::Tensor& actions);
at::Tensor DiagGaussianEntropy(const at::Tensor& mean,
                               const at::Tensor& log_std);
// KL(old || new).
at::Tensor DiagGaussianKl(const at::Tensor& old_mean,
                          const at::Tensor& old_log_std,
                          const at::Tensor& new_mean,
                          const at::Tensor& new_log_std);

// Categorical over logits [B, n]; actions are int64 indices [B].
at::Tensor CategoricalLogProb(const at::Tensor& logits,
                              const at::Tensor& actions);
at::Tensor CategoricalEntropy(const at::Tensor& logits);
// KL(old || new).
at::Tensor CategoricalKl(const at::Tensor& old_logits,
                         const at::Tensor& new_logits);

// Action masks: an illegal action's logit becomes kIllegalLogit, so that
// its probability is exactly 0 in float while every log-probability,
// entropy term (0 * finite) and KL term stays finite, which -inf would not
// give. The same value everywhere a policy acts or is scored.
constexpr float kIllegalLogit = -1e9f;

// `logits` [B, n] with the illegal entries of `masks` ([B, n] bool, 1:
// legal) replaced; `logits` itself when `masks` is undefined (no masks).
// The replaced entries pass no gradient.
at::Tensor MaskLogits(const at::Tensor& logits, const at::Tensor& masks);

// The same in place on `rows` rows of n floats, from masks of one byte per
// entry.
void MaskLogitsInPlace(float* logits, const uint8_t* masks, int64_t rows,
                       int64_t n);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_DISTRIBUTIONS_H_
