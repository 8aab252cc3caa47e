#include "learner/update/update_totals.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <vector>

#include "learner/parallel/replica_reductions.h"

namespace vantage {

namespace {

constexpr double UpdateSums::*kFields[] = {
    &UpdateSums::samples,        &UpdateSums::episodes,
    &UpdateSums::rejected,       &UpdateSums::stale_segments,
    &UpdateSums::stale_steps,    &UpdateSums::evicted_steps,
    &UpdateSums::return_sum,     &UpdateSums::return_count,
    &UpdateSums::biased_samples, &UpdateSums::abs_bias_sum,
    &UpdateSums::target_sum,     &UpdateSums::target_squares,
    &UpdateSums::residual_sum,   &UpdateSums::residual_squares,
    &UpdateSums::policy_loss,    &UpdateSums::value_loss,
    &UpdateSums::entropy,        &UpdateSums::approx_kl,
    &UpdateSums::clip_fraction};

double Sum(const at::Tensor& values) { return values.sum().item<double>(); }

}  // namespace

UpdateSums UpdateSums::Of(const PreparedBatch& prepared,
                          const AlgorithmStats& algorithm,
                          const SegmentIntake& intake) {
  const Advantages& advantages = prepared.advantages;
  const at::Tensor targets = advantages.returns.to(at::kDouble);
  const at::Tensor residual =
      targets - prepared.batch.advantage_inputs.values.to(at::kDouble);
  const SegmentIntake::Counts& counts = intake.unreported();
  const std::deque<double>& returns = intake.recent_returns();
  UpdateSums own;
  own.samples =
      static_cast<double>(prepared.update.horizon * prepared.update.streams);
  own.episodes = static_cast<double>(counts.episodes);
  own.rejected = static_cast<double>(counts.rejected);
  own.stale_segments = static_cast<double>(counts.stale_segments);
  own.stale_steps = static_cast<double>(counts.stale_steps);
  own.evicted_steps =
      static_cast<double>(intake.stitcher().stats().evicted_steps);
  own.return_sum = std::accumulate(returns.begin(), returns.end(), 0.0);
  own.return_count = static_cast<double>(returns.size());
  own.biased_samples = Sum(advantages.mask.to(at::kDouble));
  own.abs_bias_sum =
      Sum((advantages.biased - advantages.gae).abs().to(at::kDouble));
  own.target_sum = Sum(targets);
  own.target_squares = Sum(targets.pow(2));
  own.residual_sum = Sum(residual);
  own.residual_squares = Sum(residual.pow(2));
  own.policy_loss = algorithm.policy_loss;
  own.value_loss = algorithm.value_loss;
  own.entropy = algorithm.entropy;
  own.approx_kl = algorithm.approx_kl;
  own.clip_fraction = algorithm.clip_fraction;
  return own;
}

UpdateSums UpdateSums::Over(ReplicaGroup& replicas) const {
  std::vector<double> values;
  for (double UpdateSums::*field : kFields) values.push_back(this->*field);
  values = SumAcrossReplicas(replicas, values);
  UpdateSums sums;
  for (size_t i = 0; i < values.size(); ++i) sums.*kFields[i] = values[i];
  return sums;
}

void UpdateSums::AlgorithmMeans(double world_size,
                                AlgorithmStats& algorithm) const {
  algorithm.policy_loss = policy_loss / world_size;
  algorithm.value_loss = value_loss / world_size;
  algorithm.entropy = entropy / world_size;
  algorithm.approx_kl = approx_kl / world_size;
  algorithm.clip_fraction = clip_fraction / world_size;
}

void UpdateSums::BatchStatistics(UpdateStats& stats) const {
  stats.mean_return = return_count > 0
                          ? return_sum / return_count
                          : std::numeric_limits<double>::quiet_NaN();
  stats.biased_fraction = biased_samples / samples;
  stats.mean_abs_bias = abs_bias_sum / samples;
  const auto variance = [&](double sum, double squares) {
    return (squares - sum * sum / samples) / std::max(samples - 1.0, 1.0);
  };
  stats.explained_variance =
      1.0 - variance(residual_sum, residual_squares) /
                (variance(target_sum, target_squares) + 1e-8);
}

}  // namespace vantage
