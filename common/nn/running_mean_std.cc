#include "common/nn/running_mean_std.h"

#include <ATen/ATen.h>

#include "absl/strings/str_cat.h"

namespace vantage {

RunningMeanStd::RunningMeanStd(int64_t size, double initial_count)
    : count_(initial_count),
      mean_(at::zeros({size}, at::kDouble)),
      var_(at::ones({size}, at::kDouble)) {}

absl::Status RunningMeanStd::Update(const at::Tensor& batch) {
  const at::Tensor rows = batch.dim() == 1 ? batch.unsqueeze(0) : batch;
  if (rows.dim() != 2 || rows.size(1) != size()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "normaliser update needs [B, ", size(), "] values, got ", rows.dim(),
        "-d with last size ", rows.dim() > 0 ? rows.size(-1) : 0));
  }
  if (rows.size(0) == 0) return absl::OkStatus();
  const at::Tensor values = rows.to(at::kDouble);
  if (!at::isfinite(values).all().item<bool>()) {
    return absl::InvalidArgumentError(
        "normaliser update holds non-finite values; statistics unchanged");
  }
  return Merge(static_cast<double>(values.size(0)), values.mean(0),
               values.var(0, /*unbiased=*/false));
}

absl::Status RunningMeanStd::Merge(double batch_count,
                                   const at::Tensor& batch_mean,
                                   const at::Tensor& batch_var) {
  if (batch_mean.dim() != 1 || batch_mean.size(0) != size() ||
      batch_var.dim() != 1 || batch_var.size(0) != size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("normaliser merge needs moments of size ", size()));
  }
  if (batch_count == 0) return absl::OkStatus();
  if (!(batch_count > 0) || !at::isfinite(batch_mean).all().item<bool>() ||
      !at::isfinite(batch_var).all().item<bool>()) {
    return absl::InvalidArgumentError(
        "normaliser merge holds non-finite moments; statistics unchanged");
  }
  const double total = count_ + batch_count;
  const at::Tensor delta = batch_mean.to(at::kDouble) - mean_;
  mean_ = mean_ + delta * (batch_count / total);
  var_ = (var_ * count_ + batch_var.to(at::kDouble) * batch_count +
          delta * delta * (count_ * batch_count / total)) /
         total;
  count_ = total;
  return absl::OkStatus();
}

at::Tensor RunningMeanStd::Normalize(const at::Tensor& x, double clip) const {
  const at::Tensor normalized =
      (x.to(at::kDouble) - mean_) / at::sqrt(var_ + 1e-8);
  return normalized.clamp(-clip, clip).to(x.scalar_type());
}

absl::Status RunningMeanStd::Restore(double count, const at::Tensor& mean,
                                     const at::Tensor& var) {
  if (!(count > 0) || mean.dim() != 1 || var.dim() != 1 ||
      mean.size(0) != size() || var.size(0) != size()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "normaliser state needs count > 0 and mean/var of size ", size()));
  }
  const at::Tensor m = mean.to(at::kDouble);
  const at::Tensor v = var.to(at::kDouble);
  if (!at::isfinite(m).all().item<bool>() ||
      !at::isfinite(v).all().item<bool>() || (v < 0).any().item<bool>()) {
    return absl::InvalidArgumentError(
        "normaliser state has non-finite values or negative variances");
  }
  count_ = count;
  mean_ = m.clone();
  var_ = v.clone();
  return absl::OkStatus();
}

}  // namespace vantage
