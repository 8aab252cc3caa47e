#ifndef VANTAGE_DEPLOY_RUN_TRAINED_POLICY_H_
#define VANTAGE_DEPLOY_RUN_TRAINED_POLICY_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/env/environment.h"
#include "proto/run_config.pb.h"

namespace vantage {

// A policy read back from a training run's checkpoint, for evaluation.
// Its networks stay inside trained_policy.cc, so that callers compile
// without LibTorch.
struct TrainedPolicy {
  pb::RunConfig config;  // the run's resolved config
  std::string checkpoint_path;
  int64_t version = 0;
  EnvSpec spec;

  // Its sampling starts from `seed`'s random generator.
  void Seed(uint64_t seed);
  // A recurrent policy forgets what it has seen (call where an episode
  // starts); nothing for a feed-forward one.
  void StartEpisode();
  // The action for one observation: the mean (continuous) or the most
  // likely action (discrete) when `deterministic`, else a sample; among
  // the legal ones of `mask` (ReadActionMask's; empty: no masks).
  std::vector<double> Act(absl::Span<const double> observation,
                          bool deterministic,
                          absl::Span<const uint8_t> mask = {});
  // The policy and its normaliser as a serialised ONNX model
  // (deploy/export/policy_onnx.h), with the distribution's parameters too
  // when `distribution`.
  absl::StatusOr<std::string> OnnxModel(bool distribution) const;

  struct Networks;  // the policy, its normaliser and generator
  std::shared_ptr<Networks> networks;
};

// `path` is a run directory (its newest checkpoint that loads) or one
// checkpoint file.
absl::StatusOr<TrainedPolicy> LoadTrainedPolicy(const std::string& path);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_TRAINED_POLICY_H_
