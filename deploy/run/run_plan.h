#ifndef VANTAGE_DEPLOY_RUN_RUN_PLAN_H_
#define VANTAGE_DEPLOY_RUN_RUN_PLAN_H_

// A resolved run configuration turned into the typed configs of the parts
// that run it, once, without LibTorch: local training, the learner process
// and (through actor/run_settings.h, from their registration) remote actors
// all take their settings from here.

#include <string>

#include "absl/status/statusor.h"
#include "actor/actor_config.h"
#include "actor/evaluation_config.h"
#include "learner/learner_config.h"
#include "learner/run/recording_config.h"
#include "proto/run_config.pb.h"

namespace vantage {

struct RunPlan {
  // The actor of a local run (a remote actor reads its own, see
  // ActorConfigOf).
  ActorConfig actor;
  // The whole batch (training.envs streams) and everything but the env's
  // spec, which the environment itself gives.
  LearnerConfig learner;
  // Without a run directory: set by the request that names one.
  RecordingConfig recording;
  // Evaluations during training (run on the actor's side of the wiring).
  EvaluationConfig evaluation;
};

// The plan of a config that ResolveRunConfig returned; the recording's
// config_json is the config itself.
absl::StatusOr<RunPlan> PlanRun(const pb::RunConfig& resolved);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_RUN_PLAN_H_
