#ifndef VANTAGE_COMMON_NN_DISTRIBUTIONS_H_
#define VANTAGE_COMMON_NN_DISTRIBUTIONS_H_

// The policy distributions' densities, entropies and KL divergences as
// differentiable tensor functions, per sample ([B]).

#include <ATen/core/Tensor.h>

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

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_DISTRIBUTIONS_H_
