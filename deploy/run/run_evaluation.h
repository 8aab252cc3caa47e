#ifndef VANTAGE_DEPLOY_RUN_RUN_EVALUATION_H_
#define VANTAGE_DEPLOY_RUN_RUN_EVALUATION_H_

#include "absl/status/statusor.h"
#include "actor/actor_config.h"
#include "actor/evaluation_config.h"
#include "learner/run/evaluate_policy.h"

namespace vantage {

// The run's evaluations for its learner: a PolicyEvaluator of the actor's
// environment, wrapping, network and seed (the one environment is made
// here, so a bad one fails before training starts).
absl::StatusOr<EvaluatePolicy> MakeRunEvaluation(
    const ActorConfig& actor, const EvaluationConfig& evaluation);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_RUN_EVALUATION_H_
