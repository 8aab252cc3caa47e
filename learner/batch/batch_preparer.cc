#include "learner/batch/batch_preparer.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <algorithm>
#include <utility>

#include "common/nn/networks.h"
#include "common/nn/running_mean_std.h"
#include "learner/batch/reward_scaler.h"
#include "learner/exploration/ex2_bonus.h"
#include "learner/parallel/replica_group.h"

namespace vantage {

BatchPreparer::BatchPreparer(const LearnerConfig& config,
                             ValueNetworkImpl& value,
                             const RunningMeanStd& normalizer,
                             RewardScaler& reward_scaler, Ex2Bonus* exploration,
                             ReplicaGroup& replicas)
    : config_(config),
      value_(value),
      normalizer_(normalizer),
      reward_scaler_(reward_scaler),
      exploration_(exploration),
      replicas_(replicas) {}

// The batch is normalised with the statistics the acting policy used
// (shipped with its weights), so that in sync mode the first epoch's
// ratios start at 1; the statistics absorb the batch after the update.
at::Tensor BatchPreparer::Normalised(const at::Tensor& observations) const {
  return ObservationsForNetwork(config_.spec, normalizer_, observations,
                                config_.observation_clip);
}

at::Tensor BatchPreparer::Values(const at::Tensor& observations) const {
  at::NoGradGuard no_grad;
  return value_.forward(Normalised(observations));
}

absl::StatusOr<PreparedBatch> BatchPreparer::Prepare(
    std::vector<Rollout>& rollouts, int64_t version, std::mt19937_64& rng) {
  PreparedBatch prepared;
  if (exploration_ != nullptr) {
    prepared.exploration = exploration_->ShapeRewards(rollouts);
  }
  absl::StatusOr<TrainingBatch> batch = AssembleBatch(
      rollouts, [&](const at::Tensor& raw) { return Values(raw); });
  if (!batch.ok()) return batch.status();
  prepared.batch = *std::move(batch);
  AdvantageInputs& inputs = prepared.batch.advantage_inputs;
  if (config_.scale_rewards) {
    if (absl::Status status = reward_scaler_.Observe(rollouts, replicas_);
        !status.ok()) {
      return status;
    }
    inputs.rewards = reward_scaler_.Scale(inputs.rewards);
  }
  absl::StatusOr<Advantages> advantages =
      ComputeAdvantages(inputs, config_.advantage, rng);
  if (!advantages.ok()) return advantages.status();
  prepared.advantages = *std::move(advantages);
  prepared.update =
      MakeUpdateBatch(prepared.batch, prepared.advantages,
                      [&](const at::Tensor& raw) { return Normalised(raw); });
  for (const Rollout& rollout : rollouts) {
    prepared.lags.push_back(version -
                            rollout.policy_versions.min().item<int64_t>());
  }
  prepared.update.lagged =
      std::any_of(prepared.lags.begin(), prepared.lags.end(),
                  [](int64_t lag) { return lag > 0; });
  return prepared;
}

}  // namespace vantage
