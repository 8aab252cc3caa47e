#ifndef VANTAGE_LEARNER_RUN_EVALUATE_POLICY_H_
#define VANTAGE_LEARNER_RUN_EVALUATE_POLICY_H_

#include <functional>

#include "absl/status/statusor.h"
#include "common/rollout/policy_evaluation.h"

namespace vantage {

struct PolicyWeights;

// Plays a version's evaluation episodes. Deploy wires an evaluator of the
// run's environment (actor/policy_evaluator.h): the learner links none.
using EvaluatePolicy =
    std::function<absl::StatusOr<PolicyEvaluation>(const PolicyWeights&)>;

}  // namespace vantage

#endif  // VANTAGE_LEARNER_RUN_EVALUATE_POLICY_H_
