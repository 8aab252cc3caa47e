#ifndef VANTAGE_DEPLOY_TRAINED_POLICY_H_
#define VANTAGE_DEPLOY_TRAINED_POLICY_H_

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/nn/networks.h"
#include "common/nn/running_mean_std.h"
#include "proto/run_config.pb.h"

namespace vantage {

// A policy read back from a training run's checkpoint, for evaluation.
struct TrainedPolicy {
  pb::RunConfig config;  // the run's resolved config
  std::string checkpoint_path;
  int64_t version = 0;
  EnvSpec spec;
  PolicyNetwork policy{nullptr};
  RunningMeanStd normalizer{1};
  double observation_clip = 10.0;

  // The action for one observation: the mean (continuous) or the most
  // likely action (discrete) when `deterministic`, else a sample.
  std::vector<double> Act(absl::Span<const double> observation,
                          bool deterministic, at::Generator generator);
};

// `path` is a run directory (its newest checkpoint that loads) or one
// checkpoint file.
absl::StatusOr<TrainedPolicy> LoadTrainedPolicy(const std::string& path);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_TRAINED_POLICY_H_
