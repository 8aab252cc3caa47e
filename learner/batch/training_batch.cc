#include "learner/batch/training_batch.h"

#include <ATen/ATen.h>

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace vantage {

at::Tensor EpisodeStarts(const at::Tensor& terminated,
                         const at::Tensor& truncated) {
  const at::Tensor ended = at::logical_or(terminated, truncated);
  return at::cat({at::zeros({1, ended.size(1)}, at::kBool),
                  ended.slice(0, 0, ended.size(0) - 1)});
}

absl::StatusOr<TrainingBatch> AssembleBatch(
    const std::vector<Rollout>& rollouts, CriticValuesOf values_of) {
  if (rollouts.empty()) {
    return absl::InvalidArgumentError("a batch needs at least one rollout");
  }
  const int64_t steps = rollouts[0].rewards.size(0);
  const int64_t n = static_cast<int64_t>(rollouts.size());
  for (const Rollout& rollout : rollouts) {
    if (rollout.rewards.size(0) != steps) {
      return absl::InvalidArgumentError(
          absl::StrCat("rollouts of ", rollout.rewards.size(0), " and ", steps,
                       " steps cannot share a batch"));
    }
  }
  const at::Tensor values = values_of(rollouts).to(at::kFloat);
  const at::Tensor stream_values =
      values.slice(0, 0, n * (steps + 1)).reshape({n, steps + 1}).t();
  const at::Tensor final_values = values.slice(0, n * (steps + 1));

  TrainingBatch batch;
  AdvantageInputs& in = batch.advantage_inputs;
  const auto stack = [&](auto field) {
    std::vector<at::Tensor> columns;
    for (const Rollout& rollout : rollouts) columns.push_back(field(rollout));
    return at::stack(columns, 1);
  };
  in.rewards = stack([](const Rollout& r) { return r.rewards; });
  in.terminated = stack([](const Rollout& r) { return r.terminated; });
  in.truncated = stack([](const Rollout& r) { return r.truncated; });
  in.values = stream_values.slice(0, 0, steps).contiguous();
  in.last_values = stream_values[steps].contiguous();
  // Scatter V(final observation) to the truncated steps, rollout by rollout
  // in the order the finals were concatenated.
  in.truncation_values = at::zeros({steps, n}, at::kFloat);
  int64_t next_final = 0;
  for (int64_t column = 0; column < n; ++column) {
    const at::Tensor rows =
        at::nonzero(rollouts[column].truncated).reshape({-1});
    const int64_t k = rows.size(0);
    in.truncation_values.select(1, column).index_put_(
        {rows}, final_values.slice(0, next_final, next_final + k));
    next_final += k;
  }
  batch.observations = stack(
      [&](const Rollout& r) { return r.observations.slice(0, 0, steps); });
  batch.actions = stack([](const Rollout& r) { return r.actions; });
  batch.behaviour_log_probs =
      stack([](const Rollout& r) { return r.behaviour_log_probs; });
  batch.policy_versions =
      stack([](const Rollout& r) { return r.policy_versions; });
  if (rollouts[0].action_masks.defined()) {
    batch.action_masks = stack([](const Rollout& r) { return r.action_masks; });
  }
  if (std::all_of(rollouts.begin(), rollouts.end(),
                  [](const Rollout& r) { return r.episode_steps.defined(); })) {
    batch.episode_steps = stack(
        [&](const Rollout& r) { return r.episode_steps.slice(0, 0, steps); });
  }
  return batch;
}

void EndReturnsAtTimeLimits(AdvantageInputs& inputs) {
  inputs.truncation_values.zero_();
}

UpdateBatch MakeUpdateBatch(
    const TrainingBatch& batch, const Advantages& advantages,
    absl::FunctionRef<at::Tensor(const at::Tensor&)> normalize) {
  UpdateBatch update;
  update.horizon = batch.observations.size(0);
  update.streams = batch.observations.size(1);
  const int64_t samples = update.horizon * update.streams;
  update.observations = normalize(batch.observations.reshape({samples, -1}));
  update.actions = batch.actions.reshape({samples, -1});
  update.behaviour_log_probs = batch.behaviour_log_probs.reshape({samples});
  update.advantages = advantages.mixed.reshape({samples});
  update.returns = advantages.returns.reshape({samples});
  if (batch.action_masks.defined()) {
    update.action_masks = batch.action_masks.reshape({samples, -1});
  }
  if (batch.seq_len > 0) {
    update.starts = batch.starts.reshape({samples});
    update.chunk_states = batch.chunk_states;
    update.seq_len = batch.seq_len;
  }
  return update;
}

}  // namespace vantage
