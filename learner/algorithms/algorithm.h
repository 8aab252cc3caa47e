#ifndef VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_H_
#define VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_H_

// The algorithm registry: the updater of the configured algorithm.

#include <memory>

#include "absl/status/statusor.h"
#include "common/nn/networks.h"
#include "learner/algorithms/algorithm_config.h"
#include "learner/algorithms/policy_updater.h"
#include "learner/parallel/replica_group.h"

namespace vantage {

// `replicas`: the data-parallel learners the updater averages gradients
// (and the global batch's statistics) over.
absl::StatusOr<std::unique_ptr<PolicyUpdater>> MakePolicyUpdater(
    const AlgorithmConfig& config, PolicyNetwork policy, ValueNetwork value,
    std::shared_ptr<ReplicaGroup> replicas = SoloReplicaGroup());

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_H_
