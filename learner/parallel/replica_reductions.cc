#include "learner/parallel/replica_reductions.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "common/nn/running_mean_std.h"

namespace vantage {

void AverageGradients(ReplicaGroup& group,
                      const std::vector<at::Tensor>& parameters) {
  if (group.world_size() == 1 || parameters.empty()) return;
  at::NoGradGuard no_grad;
  std::vector<at::Tensor> pieces;
  pieces.reserve(parameters.size());
  for (const at::Tensor& p : parameters) {
    pieces.push_back(p.grad().defined() ? p.grad().reshape({-1})
                                        : at::zeros({p.numel()}, p.options()));
  }
  std::vector<at::Tensor> flat = {at::cat(pieces)};
  group.AllReduceSum(flat);
  flat[0].div_(group.world_size());
  int64_t offset = 0;
  for (const at::Tensor& p : parameters) {
    const int64_t n = p.numel();
    const at::Tensor mean = flat[0].slice(0, offset, offset + n).view_as(p);
    if (p.grad().defined()) {
      p.mutable_grad().copy_(mean);
    } else {
      p.mutable_grad() = mean.clone();
    }
    offset += n;
  }
}

at::Tensor AverageAcrossReplicas(ReplicaGroup& group, const at::Tensor& value) {
  if (group.world_size() == 1) return value;
  std::vector<at::Tensor> sum = {value.detach().clone().contiguous()};
  group.AllReduceSum(sum);
  return sum[0].div_(group.world_size());
}

std::vector<double> SumAcrossReplicas(ReplicaGroup& group,
                                      std::vector<double> values) {
  if (group.world_size() == 1 || values.empty()) return values;
  std::vector<at::Tensor> sum = {at::tensor(values, at::kDouble)};
  group.AllReduceSum(sum);
  const double* summed = sum[0].data_ptr<double>();
  return std::vector<double>(summed, summed + values.size());
}

at::Tensor NormalizeAcrossReplicas(ReplicaGroup& group, const at::Tensor& x) {
  const PartsNormalizer whole(group, x, {});
  return whole.Normalize(0, x);
}

PartsNormalizer::PartsNormalizer(ReplicaGroup& group, const at::Tensor& x,
                                 const std::vector<at::Tensor>& parts)
    : local_(group.world_size() == 1) {
  if (local_) return;
  // Count, sum and sum of squares of each part, in double: one pass is
  // accurate enough for advantages, and one collective serves all parts.
  const at::Tensor values = x.detach().to(at::kDouble);
  std::vector<double> moments;
  const size_t count = parts.empty() ? 1 : parts.size();
  for (size_t i = 0; i < count; ++i) {
    const at::Tensor part =
        parts.empty() ? values : values.index_select(0, parts[i]);
    moments.push_back(static_cast<double>(part.numel()));
    moments.push_back(part.sum().item<double>());
    moments.push_back(part.pow(2).sum().item<double>());
  }
  const std::vector<double> sums = SumAcrossReplicas(group, moments);
  for (size_t i = 0; i < count; ++i) {
    const double n = sums[3 * i];
    const double mean = sums[3 * i + 1] / std::max(n, 1.0);
    const double squares = sums[3 * i + 2] - n * mean * mean;
    means_.push_back(mean);
    stds_.push_back(std::sqrt(std::max(squares, 0.0) / std::max(n - 1, 1.0)));
  }
}

at::Tensor PartsNormalizer::Normalize(size_t part,
                                      const at::Tensor& values) const {
  if (local_) return (values - values.mean()) / (values.std() + 1e-8);
  return (values - means_[part]) / (stds_[part] + 1e-8);
}

void PartsNormalizer::NormalizeInPlace(size_t part, float* values,
                                       int64_t count) const {
  double mean = 0.0;
  double std = 0.0;
  if (local_) {
    for (int64_t i = 0; i < count; ++i) mean += values[i];
    mean /= static_cast<double>(std::max<int64_t>(count, 1));
    for (int64_t i = 0; i < count; ++i) {
      std += (values[i] - mean) * (values[i] - mean);
    }
    std = std::sqrt(std / static_cast<double>(std::max<int64_t>(count - 1, 1)));
  } else {
    mean = means_[part];
    std = stds_[part];
  }
  for (int64_t i = 0; i < count; ++i) {
    values[i] = static_cast<float>((values[i] - mean) / (std + 1e-8));
  }
}

absl::Status UpdateAcrossReplicas(ReplicaGroup& group, RunningMeanStd& stats,
                                  const at::Tensor& rows) {
  if (group.world_size() == 1) return stats.Update(rows);
  const int64_t size = stats.size();
  // A replica with bad rows still takes part in every collective (the
  // others would wait for it), contributing nothing but its refusal.
  bool bad = rows.dim() != 2 || rows.size(1) != size;
  at::Tensor values =
      bad ? at::zeros({0, size}, at::kDouble) : rows.detach().to(at::kDouble);
  if (!bad && !at::isfinite(values).all().item<bool>()) {
    bad = true;
    values = at::zeros({0, size}, at::kDouble);
  }
  // Two passes (sums, then squared deviations from the global mean) keep
  // the variance accurate when the mean is large against the spread.
  std::vector<at::Tensor> first = {at::cat(
      {at::tensor({static_cast<double>(values.size(0)), bad ? 1.0 : 0.0},
                  at::kDouble),
       values.sum(0)})};
  group.AllReduceSum(first);
  const double count = first[0][0].item<double>();
  const double refusals = first[0][1].item<double>();
  const at::Tensor mean = first[0].slice(0, 2) / std::max(count, 1.0);
  std::vector<at::Tensor> second = {(values - mean).pow(2).sum(0)};
  group.AllReduceSum(second);
  if (refusals > 0) {
    return absl::InvalidArgumentError(absl::StrCat(
        "normaliser update: ", refusals, " of ", group.world_size(),
        " replicas hold non-finite or wrongly sized values; statistics "
        "unchanged"));
  }
  if (count == 0) return absl::OkStatus();
  return stats.Merge(count, mean, second[0] / count);
}

}  // namespace vantage
