#ifndef VANTAGE_COMMON_NN_RECURRENT_TRUNK_H_
#define VANTAGE_COMMON_NN_RECURRENT_TRUNK_H_

// What a recurrent policy and its value network share: the torso
// (NetworkConfig::hidden tanh layers, or the convolutions) and a GRU or
// LSTM cell after it (LibTorch's cells, so that their parameters are
// weight_ih, weight_hh, bias_ih and bias_hh in LibTorch's gate order, which
// RecurrentCellKernel reads). The cell's weights are orthogonal (gain 1)
// and its biases zero, as in CleanRL's recurrent PPO.
//
// A state is one row of core_state_size() floats per environment: the
// GRU's hidden state, or the LSTM's hidden then cell state. Where an
// episode starts the state is zero.

#include <torch/nn/module.h>
#include <torch/nn/modules/rnn.h>

#include <cstdint>
#include <vector>

#include "common/env/environment.h"
#include "common/nn/network_config.h"
#include "common/nn/tanh_mlp.h"
#include "common/nn/torso.h"

namespace vantage {

class RecurrentTrunkImpl : public torch::nn::Module {
 public:
  // `config` is recurrent and its torso fits `spec` (ResolveTorso).
  RecurrentTrunkImpl(const EnvSpec& spec, const NetworkConfig& config);

  Core core() const { return core_; }
  // Units of the core: the width of features().
  int64_t features() const { return hidden_; }
  int64_t state_size() const {
    return core_ == Core::kLstm ? 2 * hidden_ : hidden_;
  }
  // Zero states for `rows` environments, [rows, state_size()].
  at::Tensor InitialState(int64_t rows) const;

  // The torso's output for network inputs (normalised observations, or
  // bytes): [rows, core input].
  at::Tensor Encode(const at::Tensor& observations);
  // One step of the core on encoded inputs from `state` [rows,
  // state_size()]: the next state.
  at::Tensor Step(const at::Tensor& encoded, const at::Tensor& state);
  // The features (hidden state) in a state [rows, features()].
  at::Tensor Hidden(const at::Tensor& state) const;

  // `steps` steps of `state.size(0)` environments: observations [steps *
  // rows, obs] time-major (row t * rows + n), `starts` [steps, rows] bool
  // (an episode starts at the step: the state is zeroed before it), from
  // `state`. The features after every step [steps * rows, features()];
  // with `after`, also the state after every step [steps, rows,
  // state_size()] (before any zeroing for the next step).
  at::Tensor Unroll(const at::Tensor& observations, const at::Tensor& starts,
                    const at::Tensor& state, at::Tensor* after = nullptr);
  // The same without autograd, each step through RecurrentCellKernel (two
  // BLAS products over all rows) instead of LibTorch's cell: for long
  // passes that train nothing, such as the critic's over a batch. Agrees
  // with Unroll up to float rounding.
  at::Tensor UnrollWithoutGradients(const at::Tensor& observations,
                                    const at::Tensor& starts,
                                    const at::Tensor& state,
                                    at::Tensor* after = nullptr);

  // Empty for the MLP torso.
  const ConvTorso& conv_torso() const { return conv_; }
  // The tanh layers (tanh after each, the last too); empty for images or
  // no --hidden layers.
  const TanhMlp& encoder() const { return encoder_; }
  // Exactly one of these is non-empty.
  const torch::nn::GRUCell& gru() const { return gru_; }
  const torch::nn::LSTMCell& lstm() const { return lstm_; }

 private:
  EnvSpec spec_;
  Core core_;
  int64_t hidden_;
  ConvTorso conv_{nullptr};
  TanhMlp encoder_{nullptr};
  torch::nn::GRUCell gru_{nullptr};
  torch::nn::LSTMCell lstm_{nullptr};
};
TORCH_MODULE(RecurrentTrunk);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_RECURRENT_TRUNK_H_
