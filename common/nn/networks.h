#ifndef VANTAGE_COMMON_NN_NETWORKS_H_
#define VANTAGE_COMMON_NN_NETWORKS_H_

// The policy and value networks: tanh MLPs with orthogonal initialisation
// (gain sqrt(2) for hidden layers, 0.01 for the policy's output, 1 for the
// value's, zero biases), as in the baselines the paper builds on, or for
// images a convolutional torso (common/nn/torso.h) and then the output
// layer. Each network has its own torso, unless the value network shares
// the policy's convolutions (NetworkConfig::shared_torso), as the A2C and
// PPO agents for Atari do. A continuous policy is a Gaussian
// with a state-independent log-std (initially 0); a discrete one is
// categorical over logits. Byte observations (EnvSpec::observation_high)
// enter as uint8 and are divided by observation_high here, so that
// nothing before the network holds a float copy of them.

#include <torch/nn/module.h>

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "common/env/environment.h"
#include "common/nn/dict_torso.h"
#include "common/nn/network_config.h"
#include "common/nn/recurrent_trunk.h"
#include "common/nn/running_mean_std.h"
#include "common/nn/tanh_mlp.h"
#include "common/nn/torso.h"

namespace vantage {

// The float inputs of the networks for `spec`: byte observations divided
// by observation_high, float ones as they are.
at::Tensor NetworkInputs(const EnvSpec& spec, const at::Tensor& observations);

// `rows` observations as an environment wrote them (doubles, row-major) in
// the dtype segments and batches hold: uint8 for byte observations (the
// values are integers in range), float32 otherwise. [rows, size].
at::Tensor ObservationTensor(const EnvSpec& spec, const double* values,
                             int64_t rows);

// Raw observations as both networks take them: real-valued ones
// normalised by `normalizer` and clipped to +-clip; byte observations are
// never normalised and stay uint8.
at::Tensor ObservationsForNetwork(const EnvSpec& spec,
                                  const RunningMeanStd& normalizer,
                                  const at::Tensor& observations, double clip);

// Both networks: `config.torso` must fit the spec (ResolveTorso).
class PolicyNetworkImpl : public torch::nn::Module {
 public:
  PolicyNetworkImpl(const EnvSpec& spec, const NetworkConfig& config);

  // Means [B, k] (continuous) or logits [B, n] (discrete). Feed-forward
  // policies only: a recurrent one needs its state (Step, Unroll).
  at::Tensor forward(const at::Tensor& observations);

  // Recurrent policies (NetworkConfig::core): the trunk they share with
  // their value network, and the output layer on its features.
  bool recurrent() const { return !trunk_.is_empty(); }
  const RecurrentTrunk& trunk() const { return trunk_; }
  at::Tensor Head(const at::Tensor& features);
  // One step of `state.size(0)` environments whose episodes go on: the
  // outputs, and `state` replaced by the next one.
  at::Tensor Step(const at::Tensor& observations, at::Tensor& state);
  // The outputs over a sequence (RecurrentTrunkImpl::Unroll's arguments).
  at::Tensor Unroll(const at::Tensor& observations, const at::Tensor& starts,
                    const at::Tensor& state);

  // From forward()'s output: per-sample log-probabilities and entropies
  // [B]. Discrete actions are indices stored as floats [B, heads] (or [B]
  // for one head); MultiDiscrete heads are independent categoricals over
  // their slices of the logits, whose log-probabilities, entropies and KL
  // divergences sum.
  at::Tensor LogProb(const at::Tensor& output, const at::Tensor& actions);
  at::Tensor Entropy(const at::Tensor& output);
  // KL(old || this) per sample from both policies' outputs.
  at::Tensor Kl(const at::Tensor& old_output, const at::Tensor& old_log_std,
                const at::Tensor& output);
  // A sampled action [B, k] ([B, heads] indices as floats when discrete),
  // or the mode when `deterministic`.
  at::Tensor Act(const at::Tensor& output, bool deterministic,
                 at::Generator generator);

  bool discrete() const { return discrete_; }
  // The discrete heads' choices (EnvSpec::action_heads).
  const std::vector<int64_t>& heads() const { return heads_; }
  int64_t HeadCount() const { return static_cast<int64_t>(heads_.size()); }
  const EnvSpec& spec() const { return spec_; }
  // Undefined for discrete policies.
  const at::Tensor& log_std() const { return log_std_; }
  // Empty for the MLP torso and for recurrent policies (their trunk's).
  const ConvTorso& conv_torso() const { return conv_; }
  // A Dict observation's torso; empty otherwise.
  const DictTorso& dict_torso() const { return dict_; }
  // The MLP (for images or a recurrent trunk, only the output layer).
  const TanhMlp& body() const { return body_; }

 private:
  // Each head's slice of a discrete policy's logits.
  std::vector<at::Tensor> Heads(const at::Tensor& output) const;

  EnvSpec spec_;
  bool discrete_;
  std::vector<int64_t> heads_;
  RecurrentTrunk trunk_{nullptr};  // recurrent only
  ConvTorso conv_{nullptr};        // images only
  DictTorso dict_{nullptr};        // Dict observations only
  TanhMlp body_{nullptr};
  at::Tensor log_std_;
};
TORCH_MODULE(PolicyNetwork);

class ValueNetworkImpl : public torch::nn::Module {
 public:
  ValueNetworkImpl(const EnvSpec& spec, const NetworkConfig& config);
  // On `shared`, a convolutional torso of another network (its parameters
  // become this network's too), with only an output layer of its own.
  ValueNetworkImpl(const EnvSpec& spec, ConvTorso shared);
  // On the trunk of a recurrent policy, with an output layer of its own.
  ValueNetworkImpl(const EnvSpec& spec, RecurrentTrunk shared);
  // For float vectors of `observation_size`.
  ValueNetworkImpl(int64_t observation_size, const NetworkConfig& config);
  // V(s) [B]; feed-forward networks only.
  at::Tensor forward(const at::Tensor& observations);
  // On a recurrent trunk: V from its features [B, features] -> [B].
  bool recurrent() const { return !trunk_.is_empty(); }
  const RecurrentTrunk& trunk() const { return trunk_; }
  at::Tensor Head(const at::Tensor& features);
  // Empty for the MLP torso; a shared torso is the policy's.
  const ConvTorso& conv_torso() const { return conv_; }
  const DictTorso& dict_torso() const { return dict_; }
  // The MLP (for images, only the output layer after the torso).
  const TanhMlp& body() const { return body_; }

 private:
  EnvSpec spec_;
  RecurrentTrunk trunk_{nullptr};
  ConvTorso conv_{nullptr};
  DictTorso dict_{nullptr};
  TanhMlp body_{nullptr};
};
TORCH_MODULE(ValueNetwork);

// The value network to train with `policy`: on the policy's recurrent
// trunk if it has one, on its torso when `config.shared_torso`, else with
// its own.
ValueNetwork MakeValueNetwork(const EnvSpec& spec, const NetworkConfig& config,
                              const PolicyNetworkImpl& policy);

// The parameters of both networks, each once (a shared torso's are the
// policy's): policy first, in registration order.
std::vector<at::Tensor> NetworkParameters(PolicyNetworkImpl& policy,
                                          ValueNetworkImpl& value);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_NETWORKS_H_
