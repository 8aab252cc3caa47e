#include "common/nn/policy_weights.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <string>

#include "absl/strings/str_cat.h"
#include "common/nn/networks.h"
#include "common/nn/running_mean_std.h"

namespace vantage {

PolicyWeights ExportPolicyWeights(PolicyNetworkImpl& policy,
                                  const RunningMeanStd& normalizer,
                                  int64_t version) {
  PolicyWeights weights;
  weights.version = version;
  for (const at::Tensor& parameter : policy.parameters()) {
    weights.parameters.push_back(parameter.detach().clone());
  }
  weights.normalizer_count = normalizer.count();
  weights.normalizer_mean = normalizer.mean().clone();
  weights.normalizer_var = normalizer.var().clone();
  return weights;
}

absl::Status ImportPolicyWeights(const PolicyWeights& weights,
                                 PolicyNetworkImpl& policy,
                                 RunningMeanStd& normalizer) {
  std::vector<at::Tensor> parameters = policy.parameters();
  if (weights.parameters.size() != parameters.size()) {
    return absl::InvalidArgumentError(
        absl::StrCat("weights hold ", weights.parameters.size(),
                     " tensors, the policy has ", parameters.size()));
  }
  for (size_t i = 0; i < parameters.size(); ++i) {
    const at::Tensor& incoming = weights.parameters[i];
    if (!incoming.defined() || incoming.sizes() != parameters[i].sizes()) {
      return absl::InvalidArgumentError(
          absl::StrCat("weight tensor ", i, " has the wrong shape"));
    }
    if (!at::isfinite(incoming).all().item<bool>()) {
      return absl::InvalidArgumentError(
          absl::StrCat("weight tensor ", i, " holds non-finite values"));
    }
  }
  // Checks the normaliser state before anything changes.
  RunningMeanStd restored(normalizer.size());
  if (absl::Status status =
          restored.Restore(weights.normalizer_count, weights.normalizer_mean,
                           weights.normalizer_var);
      !status.ok()) {
    return status;
  }
  at::NoGradGuard no_grad;
  for (size_t i = 0; i < parameters.size(); ++i) {
    parameters[i].copy_(weights.parameters[i]);
  }
  normalizer = restored;
  return absl::OkStatus();
}

}  // namespace vantage
