#ifndef VANTAGE_COMMON_NN_POLICY_WEIGHTS_H_
#define VANTAGE_COMMON_NN_POLICY_WEIGHTS_H_

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/status/status.h"

namespace vantage {

class PolicyNetworkImpl;
class RunningMeanStd;

// What the learner publishes as policy version `version`: the policy's
// parameters (in registration order) and the observation normaliser's
// state, which actors must apply exactly as the learner does.
struct PolicyWeights {
  int64_t version = 0;
  std::vector<at::Tensor> parameters;
  double normalizer_count = 0.0;
  at::Tensor normalizer_mean;
  at::Tensor normalizer_var;
};

PolicyWeights ExportPolicyWeights(PolicyNetworkImpl& policy,
                                  const RunningMeanStd& normalizer,
                                  int64_t version);

// Copies `weights` into `policy` and `normalizer` after checking every shape
// and value; on error neither is changed.
absl::Status ImportPolicyWeights(const PolicyWeights& weights,
                                 PolicyNetworkImpl& policy,
                                 RunningMeanStd& normalizer);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_POLICY_WEIGHTS_H_
