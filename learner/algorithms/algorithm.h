#ifndef VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_H_
#define VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/nn/networks.h"
#include "learner/algorithms/a2c.h"
#include "learner/algorithms/policy_updater.h"
#include "learner/algorithms/ppo.h"
#include "learner/algorithms/trpo.h"

namespace vantage {

// Which algorithm updates the networks, with every algorithm's settings
// (only the named one's are used).
struct AlgorithmConfig {
  std::string name = "ppo";  // see AlgorithmNames()
  PpoConfig ppo;
  A2cConfig a2c;
  TrpoConfig trpo;

  // An unknown name lists the valid ones.
  absl::Status Validate() const;
};

std::vector<std::string> AlgorithmNames();

absl::StatusOr<std::unique_ptr<PolicyUpdater>> MakePolicyUpdater(
    const AlgorithmConfig& config, PolicyNetwork policy, ValueNetwork value);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_ALGORITHM_H_
