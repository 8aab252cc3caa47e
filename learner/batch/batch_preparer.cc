#include "learner/batch/batch_preparer.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <algorithm>
#include <utility>

#include "common/nn/networks.h"
#include "common/nn/running_mean_std.h"
#include "learner/batch/linear_critic.h"
#include "learner/batch/recurrent_critic.h"
#include "learner/batch/reward_scaler.h"
#include "learner/exploration/ex2_bonus.h"
#include "learner/parallel/replica_group.h"

namespace vantage {

BatchPreparer::BatchPreparer(const LearnerConfig& config,
                             ValueNetworkImpl& value,
                             const RunningMeanStd& normalizer,
                             RewardScaler& reward_scaler, Ex2Bonus* exploration,
                             ReplicaGroup& replicas,
                             const LinearCritic* linear_critic)
    : config_(config),
      value_(value),
      normalizer_(normalizer),
      reward_scaler_(reward_scaler),
      exploration_(exploration),
      replicas_(replicas),
      linear_critic_(linear_critic) {}

// The batch is normalised with the statistics the acting policy used
// (shipped with its weights), so that in sync mode the first epoch's
// ratios start at 1; the statistics absorb the batch after the update.
at::Tensor BatchPreparer::Normalised(const at::Tensor& observations) const {
  return ObservationsForNetwork(config_.spec, normalizer_, observations,
                                config_.observation_clip);
}

at::Tensor BatchPreparer::Values(const std::vector<Rollout>& rollouts) const {
  std::vector<at::Tensor> observations, finals;
  for (const Rollout& rollout : rollouts) {
    observations.push_back(rollout.observations);
    finals.push_back(rollout.final_observations);
  }
  at::NoGradGuard no_grad;
  // One critic pass: every rollout's T + 1 observations, then the finals.
  return value_.forward(
      Normalised(at::cat({at::cat(observations), at::cat(finals)})));
}

absl::StatusOr<TrainingBatch> BatchPreparer::Assemble(
    const std::vector<Rollout>& rollouts) const {
  if (config_.zero_critic()) {
    return AssembleBatch(rollouts, [](const std::vector<Rollout>& r) {
      int64_t rows = 0;
      for (const Rollout& rollout : r) {
        rows +=
            rollout.observations.size(0) + rollout.final_observations.size(0);
      }
      return at::zeros({rows}, at::kFloat);
    });
  }
  if (linear_critic_ != nullptr) {
    absl::StatusOr<at::Tensor> values = linear_critic_->Values(rollouts);
    if (!values.ok()) return values.status();
    return AssembleBatch(rollouts,
                         [&](const std::vector<Rollout>&) { return *values; });
  }
  if (!value_.recurrent()) {
    return AssembleBatch(
        rollouts, [&](const std::vector<Rollout>& r) { return Values(r); });
  }
  RecurrentCriticPass pass;
  absl::StatusOr<TrainingBatch> batch =
      AssembleBatch(rollouts, [&](const std::vector<Rollout>& r) {
        pass = RunRecurrentCritic(
            value_, r, [&](const at::Tensor& raw) { return Normalised(raw); });
        return pass.values;
      });
  if (!batch.ok()) return batch;
  batch->seq_len = config_.network.seq_len;
  batch->starts = EpisodeStarts(batch->advantage_inputs.terminated,
                                batch->advantage_inputs.truncated);
  batch->chunk_states = ChunkStartStates(pass, batch->seq_len);
  return batch;
}

absl::StatusOr<PreparedBatch> BatchPreparer::Prepare(
    std::vector<Rollout>& rollouts, int64_t version, std::mt19937_64& rng) {
  PreparedBatch prepared;
  if (exploration_ != nullptr) {
    prepared.exploration = exploration_->ShapeRewards(rollouts);
  }
  absl::StatusOr<TrainingBatch> batch = Assemble(rollouts);
  if (!batch.ok()) return batch.status();
  prepared.batch = *std::move(batch);
  AdvantageInputs& inputs = prepared.batch.advantage_inputs;
  if (!config_.bootstrap_time_limits) EndReturnsAtTimeLimits(inputs);
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
