#ifndef VANTAGE_LEARNER_ALGORITHMS_FLAT_ACTOR_CRITIC_H_
#define VANTAGE_LEARNER_ALGORITHMS_FLAT_ACTOR_CRITIC_H_

// The MLP policy and value networks as the first-order algorithms train
// them, without autograd: every parameter in one flat float array (the
// order of NetworkParameters), the forward pass of a minibatch as one BLAS
// call per layer keeping what the backward pass needs, the policy head's
// log-probabilities and entropies, and the backward pass written out by
// hand into one flat gradient array. A minibatch step on a 64x64 network
// is a few dozen small kernels instead of LibTorch's hundreds of operator
// dispatches and autograd nodes; tests/learner/algorithms/
// flat_actor_critic_test.cc checks every gradient against autograd.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "common/env/environment.h"
#include "learner/algorithms/flat_mlp.h"
#include "learner/algorithms/flat_recurrent_core.h"

namespace vantage {

class PolicyNetworkImpl;
class ValueNetworkImpl;

class FlatActorCritic {
 public:
  // `parameters`: NetworkParameters(policy, value). Unimplemented for what
  // it cannot run (a convolutional torso, a shared one); those networks
  // train through autograd.
  static absl::StatusOr<FlatActorCritic> Create(
      PolicyNetworkImpl& policy, ValueNetworkImpl& value,
      std::vector<at::Tensor> parameters);

  int64_t size() const { return static_cast<int64_t>(parameters_.size()); }
  float* parameters() { return parameters_.data(); }
  const float* gradients() const { return gradients_.data(); }
  float* gradients() { return gradients_.data(); }
  // Where each parameter tensor's values begin in the flat arrays.
  const std::vector<int64_t>& offsets() const { return offsets_; }
  int64_t observation_size() const { return spec_.observation_size; }
  int64_t action_width() const {
    return discrete_ ? static_cast<int64_t>(heads_.size()) : spec_.action_size;
  }

  // The modules' parameters into the flat array, and back.
  void Pull();
  void Push();

  // The inputs of both networks [rows, observation_size] for observations
  // as batches hold them (normalised floats, or bytes, which the networks
  // divide by observation_high).
  at::Tensor Inputs(const at::Tensor& observations) const;

  // Both networks on `rows` inputs, and the policy's log-probabilities of
  // `actions` ([rows, action_width()]; indices as floats when discrete).
  // Masked discrete actions score the policy under `masks` ([rows,
  // actions] bytes, 1: legal; null: no masks). Every array must stay
  // unchanged until Backward. Feed-forward networks.
  void Forward(const float* inputs, const float* actions, int64_t rows,
               const uint8_t* masks = nullptr);

  // Networks with a recurrent core (FlatRecurrentCore): the same over
  // `steps` steps of `chunks` sequences, rows time-major (step t of chunk j
  // at t * chunks + j), `starts` [rows] marking episode starts, `states`
  // [chunks, state_size()] the chunks' start states. Every array must stay
  // unchanged until Backward.
  bool recurrent() const { return core_.has_value(); }
  int64_t state_size() const { return core_ ? core_->state_size() : 0; }
  void ForwardSequences(const float* inputs, const float* actions,
                        const uint8_t* starts, const float* states,
                        int64_t steps, int64_t chunks,
                        const uint8_t* masks = nullptr);
  const float* log_probs() const { return log_probs_.data(); }  // [rows]
  const float* values() const { return values_.data(); }        // [rows]
  // The mean over the rows of the policy's entropy.
  double mean_entropy() const { return mean_entropy_; }

  // gradients() := the gradient of
  //   sum_i d_log_probs[i] * log_prob_i + entropy_weight * mean_entropy
  //   + sum_i d_values[i] * value_i
  // for the rows of the last Forward.
  void Backward(const float* d_log_probs, double entropy_weight,
                const float* d_values);

 private:
  FlatActorCritic() = default;
  // Create's steps. LayOutNetworks fails unless every parameter is claimed
  // exactly once, by a layer or the log-std: the flat arrays must cover the
  // networks and nothing else.
  absl::Status LayOutNetworks(PolicyNetworkImpl& policy,
                              ValueNetworkImpl& value,
                              FlatParameterClaims& claims);
  // A recurrent trunk: its encoder, its cell; then both heads on its
  // features.
  absl::Status LayOutRecurrent(PolicyNetworkImpl& policy,
                               ValueNetworkImpl& value,
                               FlatParameterClaims& claims);
  // The values and log-probabilities after both networks' forward passes.
  void Heads(const float* actions, const uint8_t* masks, int64_t rows);
  // Backward's path through a recurrent trunk from both heads' gradients.
  void TrunkBackward(int64_t rows);
  void GaussianHead(const float* actions, int64_t rows);
  void CategoricalHead(const float* actions, const uint8_t* masks,
                       int64_t rows);

  EnvSpec spec_;
  bool discrete_ = false;
  std::vector<int64_t> heads_;  // discrete: each head's choices
  std::vector<at::Tensor> tensors_;
  std::vector<int64_t> offsets_;
  std::vector<float> parameters_;
  std::vector<float> gradients_;
  FlatMlp policy_;
  FlatMlp value_;
  // A recurrent trunk's (the heads above then read its features).
  FlatMlp encoder_;
  std::optional<FlatRecurrentCore> core_;
  std::vector<float> d_features_, d_value_features_, d_encoded_;
  int64_t log_std_ = -1;  // offset; continuous only

  // The last Forward's rows and what Backward needs of them.
  int64_t rows_ = 0;
  const float* inputs_ = nullptr;
  const float* actions_ = nullptr;
  std::vector<float> log_probs_, values_;
  double mean_entropy_ = 0.0;
  // Per row and action: z = (action - mean) / std (Gaussian), or the
  // log-softmax of the logits (categorical).
  std::vector<float> head_;
  std::vector<float> entropies_;  // per row and head (categorical)
  std::vector<float> policy_gradient_, value_gradient_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_FLAT_ACTOR_CRITIC_H_
