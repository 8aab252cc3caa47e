#include "learner/learner_config.h"

#include "absl/strings/str_cat.h"
#include "learner/algorithms/trpo/trpo_config.h"

namespace vantage {

bool LearnerConfig::linear_critic() const {
  return algorithm.name == "trpo" &&
         algorithm.Get<TrpoConfig>().linear_baseline;
}

bool LearnerConfig::zero_critic() const {
  return algorithm.name == "trpo" && algorithm.Get<TrpoConfig>().zero_baseline;
}

absl::Status LearnerConfig::Validate() const {
  if (spec.observation_size < 1 || spec.action_size < 1) {
    return absl::InvalidArgumentError("learner needs an environment spec");
  }
  if (absl::Status status = CheckObservationLayout(spec); !status.ok()) {
    return status;
  }
  if (absl::Status status = CheckNetworkConfig(network, spec); !status.ok()) {
    return status;
  }
  if (linear_critic() &&
      (spec.byte_observations() || !spec.observation_keys.empty())) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--trpo_linear_baseline fits the observations' values and squares; ",
        spec.name, "'s observations are ",
        spec.byte_observations() ? "images (bytes)" : "a Dict or Tuple",
        ": use the value network"));
  }
  if (exploration.ex2.has_value() && exploration.ex2->convolutional() &&
      spec.observation_shape.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--ex2_encoder=conv convolves an image observation; ", spec.name,
        "'s observations are ",
        spec.observation_keys.empty() ? "a vector" : "a Dict or Tuple",
        ": use --ex2_encoder=mlp"));
  }
  return ValidateSettings();
}

absl::Status LearnerConfig::ValidateSettings() const {
  if (network.shared_torso && !AlgorithmStepsBothNetworksAtOnce(algorithm)) {
    return absl::InvalidArgumentError(
        absl::StrCat("--shared_torso needs ppo or a2c, which step both "
                     "networks with one optimiser; ",
                     algorithm.name, " fits its value network alone"));
  }
  if (network.recurrent() && !AlgorithmStepsBothNetworksAtOnce(algorithm)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--core=", CoreName(network.core),
        " needs ppo or a2c: the policy and the value network share the core "
        "and step with one optimiser; ",
        algorithm.name, " fits its value network alone"));
  }
  if (network.recurrent() &&
      (network.seq_len < 1 || horizon % network.seq_len != 0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--seq_len (", network.seq_len, ") must divide --horizon (", horizon,
        ") for a recurrent --core"));
  }
  if (horizon < 1 || rollouts_per_batch < 1 || total_env_steps < 1) {
    return absl::InvalidArgumentError(
        "learner horizon, rollouts_per_batch and total_env_steps must be "
        ">= 1");
  }
  if (!(observation_clip > 0) || !(reward_clip > 0)) {
    return absl::InvalidArgumentError(
        "observation_clip and reward_clip must be > 0");
  }
  if (max_buffered_steps < 0) {
    return absl::InvalidArgumentError(
        absl::StrCat("max_buffered_steps must be >= 0 (0: 8 batches), got ",
                     max_buffered_steps));
  }
  if (!(rollback_gradient_norm > 0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "rollback_gradient_norm must be > 0, got ", rollback_gradient_norm));
  }
  if (absl::Status status = value_limits.Validate(); !status.ok()) {
    return status;
  }
  if (absl::Status status = advantage.Validate(); !status.ok()) return status;
  if (absl::Status status = algorithm.Validate(); !status.ok()) return status;
  if (exploration.ex2.has_value()) {
    if (absl::Status status = exploration.ex2->Validate(); !status.ok()) {
      return status;
    }
  }
  const int64_t multiple = RunDefaultsOf(algorithm).horizon_multiple;
  if (multiple > 1 && horizon % multiple != 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(algorithm.name,
                     " needs a horizon that is a multiple of "
                     "its ",
                     multiple, "-step minibatches; got ", horizon));
  }
  return absl::OkStatus();
}

}  // namespace vantage
