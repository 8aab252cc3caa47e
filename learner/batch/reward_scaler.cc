#include "learner/batch/reward_scaler.h"

#include <ATen/ATen.h>
#include <torch/serialize/archive.h>

#include <cmath>

#include "learner/checkpoint/archive_io.h"
#include "learner/parallel/replica_reductions.h"

namespace vantage {

RewardScaler::RewardScaler(double gamma, double clip)
    : gamma_(gamma), clip_(clip), returns_(1) {}

absl::Status RewardScaler::Observe(const std::vector<Rollout>& rollouts,
                                   ReplicaGroup& replicas) {
  std::map<std::pair<int64_t, int64_t>, double> running = running_return_;
  std::vector<double> samples;
  for (const Rollout& rollout : rollouts) {
    double& value = running[{rollout.actor_id, rollout.env_slot}];
    const at::Tensor rewards = rollout.rewards.to(at::kDouble).contiguous();
    const at::Tensor ended =
        at::logical_or(rollout.terminated, rollout.truncated).contiguous();
    const double* r = rewards.data_ptr<double>();
    const bool* done = ended.data_ptr<bool>();
    for (int64_t t = 0; t < rewards.size(0); ++t) {
      value = gamma_ * value + r[t];
      samples.push_back(value);
      if (done[t]) value = 0.0;
    }
  }
  const at::Tensor batch = at::tensor(samples, at::kDouble).reshape({-1, 1});
  if (absl::Status status = UpdateAcrossReplicas(replicas, returns_, batch);
      !status.ok()) {
    return status;
  }
  running_return_ = std::move(running);
  return absl::OkStatus();
}

at::Tensor RewardScaler::Scale(const at::Tensor& rewards) const {
  const double scale = 1.0 / std::sqrt(returns_.var().item<double>() + 1e-8);
  return (rewards * scale).clamp(-clip_, clip_);
}

void RewardScaler::Save(torch::serialize::OutputArchive& archive) const {
  std::vector<int64_t> keys;
  std::vector<double> values;
  for (const auto& entry : running_return_) {
    keys.push_back(entry.first.first);
    keys.push_back(entry.first.second);
    values.push_back(entry.second);
  }
  WriteRunningMeanStd(archive, "returns", returns_);
  archive.write("streams", at::tensor(keys, at::kLong));
  archive.write("running_returns", at::tensor(values, at::kDouble));
}

absl::Status RewardScaler::Load(torch::serialize::InputArchive& archive) {
  at::Tensor keys, values;
  RunningMeanStd returns = returns_;
  for (absl::Status status : {ReadRunningMeanStd(archive, "returns", returns),
                              ReadTensor(archive, "streams", keys),
                              ReadTensor(archive, "running_returns", values)}) {
    if (!status.ok()) return status;
  }
  if (keys.scalar_type() != at::kLong || values.scalar_type() != at::kDouble ||
      keys.dim() != 1 || values.dim() != 1 ||
      keys.numel() != 2 * values.numel()) {
    return absl::InvalidArgumentError(
        "checkpoint entries 'streams' and 'running_returns' do not match");
  }
  std::map<std::pair<int64_t, int64_t>, double> running;
  for (int64_t i = 0; i < values.numel(); ++i) {
    running[{keys[2 * i].item<int64_t>(), keys[2 * i + 1].item<int64_t>()}] =
        values[i].item<double>();
  }
  returns_ = std::move(returns);
  running_return_ = std::move(running);
  return absl::OkStatus();
}

}  // namespace vantage
