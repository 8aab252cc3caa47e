#ifndef VANTAGE_COMMON_NN_POLICY_RUNNER_H_
#define VANTAGE_COMMON_NN_POLICY_RUNNER_H_

// One policy acting on one environment step by step outside training (a
// trained policy's rollouts, evaluations during training), through
// LibTorch: the policy network, its observation normaliser and, for a
// recurrent policy, the state it carries through an episode.

#include <ATen/core/Generator.h>
#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "absl/types/span.h"
#include "common/env/environment.h"
#include "common/nn/network_config.h"
#include "common/nn/networks.h"
#include "common/nn/policy_weights.h"
#include "common/nn/running_mean_std.h"

namespace vantage {

class PolicyRunner {
 public:
  PolicyRunner(const EnvSpec& spec, const NetworkConfig& network,
               double observation_clip);

  // The version's weights (checked as ImportPolicyWeights checks them); a
  // recurrent policy starts an episode.
  absl::Status Load(const PolicyWeights& weights);
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

  const EnvSpec& spec() const { return spec_; }
  PolicyNetworkImpl& policy() const { return *policy_.ptr(); }
  const RunningMeanStd& normalizer() const { return normalizer_; }
  double observation_clip() const { return observation_clip_; }

 private:
  EnvSpec spec_;
  PolicyNetwork policy_;
  RunningMeanStd normalizer_;
  double observation_clip_;
  at::Generator generator_;
  at::Tensor state_;  // a recurrent policy's, [1, state size]
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_POLICY_RUNNER_H_
