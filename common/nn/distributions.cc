#include "common/nn/distributions.h"

#include <ATen/ATen.h>

#include <cmath>

namespace vantage {

at::Tensor DiagGaussianLogProb(const at::Tensor& mean,
                               const at::Tensor& log_std,
                               const at::Tensor& actions) {
  const at::Tensor z = (actions - mean) * at::exp(-log_std);
  return (-0.5 * z * z - log_std - kLogSqrtTwoPi).sum(-1);
}

at::Tensor DiagGaussianEntropy(const at::Tensor& mean,
                               const at::Tensor& log_std) {
  // 0.5 * log(2 pi e) + log_std per dimension.
  return (log_std + (kLogSqrtTwoPi + 0.5)).expand_as(mean).sum(-1);
}

at::Tensor DiagGaussianKl(const at::Tensor& old_mean,
                          const at::Tensor& old_log_std,
                          const at::Tensor& new_mean,
                          const at::Tensor& new_log_std) {
  const at::Tensor old_var = at::exp(2.0 * old_log_std);
  const at::Tensor new_var = at::exp(2.0 * new_log_std);
  const at::Tensor diff = old_mean - new_mean;
  return (new_log_std - old_log_std +
          (old_var + diff * diff) / (2.0 * new_var) - 0.5)
      .sum(-1);
}

at::Tensor CategoricalLogProb(const at::Tensor& logits,
                              const at::Tensor& actions) {
  return at::log_softmax(logits, -1)
      .gather(-1, actions.to(at::kLong).unsqueeze(-1))
      .squeeze(-1);
}

at::Tensor CategoricalEntropy(const at::Tensor& logits) {
  const at::Tensor log_p = at::log_softmax(logits, -1);
  return -(at::exp(log_p) * log_p).sum(-1);
}

at::Tensor CategoricalKl(const at::Tensor& old_logits,
                         const at::Tensor& new_logits) {
  const at::Tensor old_log_p = at::log_softmax(old_logits, -1);
  const at::Tensor new_log_p = at::log_softmax(new_logits, -1);
  return (at::exp(old_log_p) * (old_log_p - new_log_p)).sum(-1);
}

at::Tensor MaskLogits(const at::Tensor& logits, const at::Tensor& masks) {
  if (!masks.defined()) return logits;
  return logits.masked_fill(masks.logical_not(), kIllegalLogit);
}

void MaskLogitsInPlace(float* logits, const uint8_t* masks, int64_t rows,
                       int64_t n) {
  for (int64_t i = 0, size = rows * n; i < size; ++i) {
    if (!masks[i]) logits[i] = kIllegalLogit;
  }
}

}  // namespace vantage
