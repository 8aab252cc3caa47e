#ifndef VANTAGE_DEPLOY_EXPORT_POLICY_ONNX_H_
#define VANTAGE_DEPLOY_EXPORT_POLICY_ONNX_H_

// A trained policy as an ONNX model (opset 10), for programs and runtimes
// outside vantage: one input `observation` [batch, observation size]
// (float: the values the environment gives; byte observations as their
// values; a Dict's entries side by side in the spec's order, images
// channels first), the observation normaliser inside the graph exactly as the
// networks take it, and the output `action`: the Gaussian mean clipped to
// the action bounds (float [batch, k]) or the most likely action (int64
// [batch]). With `distribution`, also the distribution's parameters:
// `mean` and `log_std` (each [batch, k]) or `logits` [batch, n]. A policy
// of masked discrete actions has a second input, `action_mask` (float
// [batch, n], 1 for a legal action, 0 for an illegal one): the action is
// the most likely legal one and an illegal action's logit is -1e9, as in
// vantage. The model passes ONNX's checker before it is returned.

#include <string>

#include "absl/status/statusor.h"
#include "common/env/environment.h"

namespace vantage {

class PolicyNetworkImpl;
class RunningMeanStd;

struct OnnxExportOptions {
  bool distribution = false;
  std::string producer_version;  // the model's producer_version
};

// The serialised model. Unimplemented, naming what, for a policy it cannot
// express (a recurrent core).
absl::StatusOr<std::string> PolicyToOnnx(const EnvSpec& spec,
                                         PolicyNetworkImpl& policy,
                                         const RunningMeanStd& normalizer,
                                         double observation_clip,
                                         const OnnxExportOptions& options);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_EXPORT_POLICY_ONNX_H_
