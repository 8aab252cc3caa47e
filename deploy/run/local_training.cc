#include "deploy/run/local_training.h"

#include "absl/strings/str_cat.h"
#include "actor/actor_core.h"
#include "deploy/run/run_evaluation.h"
#include "learner/checkpoint/checkpoint.h"
#include "learner/learner_core.h"
#include "learner/run/training_run.h"

namespace vantage {
namespace {

constexpr char kActorState[] = "actor_state";

// Before the row of each evaluated version, so that the row holds it and a
// rerun or a resume repeats it.
absl::Status EvaluateLocally(const RunPlan& plan, TrainingRun& run) {
  if (!plan.evaluation.enabled()) return absl::OkStatus();
  absl::StatusOr<EvaluatePolicy> evaluate =
      MakeRunEvaluation(plan.actor, plan.evaluation);
  if (!evaluate.ok()) return evaluate.status();
  return run.EvaluateEvery(plan.evaluation.every, *std::move(evaluate),
                           /*in_background=*/false);
}

}  // namespace

absl::Status RunLocalTraining(
    const RunPlan& plan,
    const std::function<bool(const ProgressRow&)>& on_update,
    const std::atomic<bool>* stop) {
  const int64_t horizon = plan.learner.horizon;
  if (horizon % plan.actor.segment_length != 0) {
    return absl::InvalidArgumentError(
        "the segment length must divide the horizon");
  }
  if (plan.actor.num_envs != plan.learner.rollouts_per_batch) {
    return absl::InvalidArgumentError(
        absl::StrCat("a local run's batch is its actor's ", plan.actor.num_envs,
                     " env streams, not ", plan.learner.rollouts_per_batch));
  }
  const int64_t rounds = horizon / plan.actor.segment_length;
  absl::StatusOr<std::unique_ptr<ActorCore>> actor =
      ActorCore::Create(plan.actor);
  if (!actor.ok()) return actor.status();

  LearnerConfig learner_config = plan.learner;
  learner_config.spec = (*actor)->spec();
  // The actor continues exactly where the checkpoint's actor was.
  absl::StatusOr<std::unique_ptr<TrainingRun>> run = TrainingRun::Open(
      plan.recording, learner_config,
      [&](const std::string& path, const CheckpointExtras& extras) {
        auto state = extras.find(kActorState);
        if (state == extras.end()) {
          return absl::InvalidArgumentError(
              absl::StrCat(path, " holds no actor state"));
        }
        return (*actor)->RestoreState(state->second);
      });
  if (!run.ok()) return run.status();
  if (absl::Status status = EvaluateLocally(plan, **run); !status.ok()) {
    return status;
  }
  LearnerCore& learner = (*run)->learner();
  auto actor_state = [&]() -> absl::StatusOr<CheckpointExtras> {
    absl::StatusOr<std::string> state = (*actor)->SaveState();
    if (!state.ok()) return state.status();
    return CheckpointExtras{{kActorState, *std::move(state)}};
  };

  // One horizon of segments per version, all queued before the update.
  SegmentQueue queue(static_cast<size_t>(plan.actor.num_envs * rounds));
  while (!(*run)->done()) {
    if (stop != nullptr && *stop) return (*run)->CheckpointNow(actor_state);
    if (absl::Status status = (*actor)->SetWeights(learner.CurrentWeights());
        !status.ok()) {
      return status;
    }
    for (int64_t round = 0; round < rounds; ++round) {
      if (absl::Status status = (*actor)->CollectSegments(queue);
          !status.ok()) {
        return status;
      }
    }
    absl::StatusOr<ProgressRow> progress = (*run)->Update(queue, actor_state);
    if (!progress.ok()) return progress.status();
    if (!on_update(*progress)) break;
  }
  return absl::OkStatus();
}

}  // namespace vantage
