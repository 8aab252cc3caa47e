#include "deploy/run/run_plan.h"

#include "absl/strings/str_cat.h"
#include "actor/evaluation_config.h"
#include "actor/run_settings.h"
#include "deploy/run/run_config_file.h"
#include "learner/learner_settings.h"

namespace vantage {

absl::StatusOr<RunPlan> PlanRun(const pb::RunConfig& resolved) {
  RunPlan plan;
  absl::StatusOr<ActorConfig> actor = ActorConfigOf(resolved);
  if (!actor.ok()) return actor.status();
  plan.actor = *std::move(actor);
  absl::StatusOr<LearnerConfig> learner = LearnerConfigOf(resolved);
  if (!learner.ok()) return learner.status();
  plan.learner = *std::move(learner);
  // The learner trains the network its actors run, and both clip
  // observations alike.
  plan.learner.network = plan.actor.network;
  plan.learner.observation_clip = plan.actor.observation_clip;
  plan.recording = RecordingConfigOf(resolved.recording());
  plan.recording.config_json = RunConfigToJson(resolved);
  plan.evaluation = EvaluationConfigOf(resolved);
  return plan;
}

}  // namespace vantage
