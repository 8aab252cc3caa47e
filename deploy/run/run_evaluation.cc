#include "deploy/run/run_evaluation.h"

#include <memory>
#include <utility>

#include "actor/policy_evaluator.h"

namespace vantage {

absl::StatusOr<EvaluatePolicy> MakeRunEvaluation(
    const ActorConfig& actor, const EvaluationConfig& evaluation) {
  absl::StatusOr<std::unique_ptr<PolicyEvaluator>> made =
      PolicyEvaluator::Create(actor, evaluation.episodes);
  if (!made.ok()) return made.status();
  std::shared_ptr<PolicyEvaluator> evaluator = *std::move(made);
  return EvaluatePolicy([evaluator](const PolicyWeights& weights) {
    return evaluator->Evaluate(weights);
  });
}

}  // namespace vantage
