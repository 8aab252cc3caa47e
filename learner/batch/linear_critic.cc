#include "learner/batch/linear_critic.h"

#include <ATen/ATen.h>
#include <torch/serialize/archive.h>

#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "learner/checkpoint/archive_io.h"
#include "learner/parallel/replica_group.h"

namespace vantage {

LinearCritic::LinearCritic(int64_t observation_size)
    : coefficients_(at::zeros({2 * observation_size + 4}, at::kDouble)) {}

at::Tensor LinearCritic::Features(const at::Tensor& observations,
                                  const at::Tensor& episode_steps) {
  const at::Tensor s = observations.to(at::kDouble).clamp(-10.0, 10.0);
  const at::Tensor t = episode_steps.to(at::kDouble).reshape({-1, 1}) / 100.0;
  return at::cat({s, s * s, t, t * t, t * t * t, at::ones_like(t)}, 1);
}

at::Tensor LinearCritic::Predict(const at::Tensor& features) const {
  return at::mv(features, coefficients_).to(at::kFloat);
}

absl::StatusOr<at::Tensor> LinearCritic::Values(
    const std::vector<Rollout>& rollouts) const {
  std::vector<at::Tensor> observations, steps, finals, final_steps;
  for (const Rollout& rollout : rollouts) {
    if (!rollout.episode_steps.defined() ||
        rollout.episode_steps.numel() != rollout.observations.size(0)) {
      return absl::InvalidArgumentError(absl::StrCat(
          "the rollout of actor ", rollout.actor_id, " slot ", rollout.env_slot,
          " does not say which step of its episode each observation is, "
          "which the linear critic reads"));
    }
    observations.push_back(rollout.observations);
    steps.push_back(rollout.episode_steps);
    // A truncated step's final observation is one step after the step.
    const at::Tensor rows = at::nonzero(rollout.truncated).reshape({-1});
    finals.push_back(rollout.final_observations);
    final_steps.push_back(rollout.episode_steps.index_select(0, rows) + 1);
  }
  const at::Tensor features =
      Features(at::cat({at::cat(observations), at::cat(finals)}),
               at::cat({at::cat(steps), at::cat(final_steps)}));
  return Predict(features);
}

absl::StatusOr<double> LinearCritic::Fit(const at::Tensor& features,
                                         const at::Tensor& targets,
                                         ReplicaGroup& replicas) {
  const at::Tensor y = targets.to(at::kDouble).reshape({-1});
  std::vector<at::Tensor> sums = {at::mm(features.t(), features),
                                  at::mv(features.t(), y)};
  replicas.AllReduceSum(sums);
  const int64_t width = features.size(1);
  const at::Tensor identity = at::eye(width, at::kDouble);
  double ridge = kRidge;
  at::Tensor solution;
  for (int attempt = 0; attempt < kSolveAttempts; ++attempt, ridge *= 10) {
    at::Tensor candidate;
    try {
      candidate =
          at::linalg_solve(sums[0] + ridge * identity, sums[1].unsqueeze(1))
              .squeeze(1);
    } catch (const c10::Error&) {
      continue;  // singular to LAPACK: a larger ridge may do
    }
    if (at::isfinite(candidate).all().item<bool>()) {
      solution = candidate;
      break;
    }
  }
  if (!solution.defined()) {
    return absl::FailedPreconditionError(absl::StrCat(
        "the linear critic's least squares stayed non-finite up to ridge ",
        ridge / 10, "; its weights are as before"));
  }
  coefficients_ = solution;
  const at::Tensor error = at::mv(features, coefficients_) - y;
  std::vector<at::Tensor> totals = {at::stack(
      {(error * error).sum(),
       at::scalar_tensor(static_cast<double>(y.numel()), at::kDouble)})};
  replicas.AllReduceSum(totals);
  const double rows = totals[0][1].item<double>();
  return rows > 0 ? totals[0][0].item<double>() / rows : 0.0;
}

void LinearCritic::Save(torch::serialize::OutputArchive& archive) const {
  archive.write("coefficients", coefficients_);
}

absl::Status LinearCritic::Load(torch::serialize::InputArchive& archive) {
  at::Tensor coefficients;
  if (absl::Status status = ReadTensor(archive, "coefficients", coefficients);
      !status.ok()) {
    return status;
  }
  return Restore(coefficients);
}

absl::Status LinearCritic::Restore(const at::Tensor& coefficients) {
  if (coefficients.scalar_type() != at::kDouble ||
      !coefficients.sizes().equals(coefficients_.sizes()) ||
      !at::isfinite(coefficients).all().item<bool>()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "checkpoint entry 'coefficients' of the linear critic must hold ",
        coefficients_.numel(), " finite doubles (2 x the observation size + ",
        "4)"));
  }
  coefficients_ = coefficients.clone();
  return absl::OkStatus();
}

}  // namespace vantage
