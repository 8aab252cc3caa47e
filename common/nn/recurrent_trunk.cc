#include "common/nn/recurrent_trunk.h"

#include <ATen/ATen.h>
#include <torch/nn/init.h>

#include <cmath>
#include <tuple>

#include "common/nn/networks.h"

namespace vantage {
namespace {

void InitialiseCell(torch::nn::Module& cell) {
  for (auto& named : cell.named_parameters()) {
    at::Tensor& parameter = named.value();
    if (parameter.dim() >= 2) {
      torch::nn::init::orthogonal_(parameter, 1.0);
    } else {
      torch::nn::init::zeros_(parameter);
    }
  }
}

}  // namespace

RecurrentTrunkImpl::RecurrentTrunkImpl(const EnvSpec& spec,
                                       const NetworkConfig& config)
    : spec_(spec), core_(config.core), hidden_(config.core_size) {
  const Torso torso = ResolveTorso(config.torso, spec).value();
  int64_t inputs = spec.observation_size;
  if (torso != Torso::kMlp) {
    conv_ = register_module("conv", ConvTorso(torso, spec.observation_shape));
    inputs = conv_->features();
  } else if (!config.hidden.empty()) {
    const std::vector<int64_t> inner(config.hidden.begin(),
                                     config.hidden.end() - 1);
    encoder_ = register_module(
        "encoder",
        TanhMlp(inputs, inner, config.hidden.back(), std::sqrt(2.0)));
    inputs = config.hidden.back();
  }
  if (core_ == Core::kLstm) {
    lstm_ = register_module("core", torch::nn::LSTMCell(inputs, hidden_));
    InitialiseCell(*lstm_);
  } else {
    gru_ = register_module("core", torch::nn::GRUCell(inputs, hidden_));
    InitialiseCell(*gru_);
  }
}

at::Tensor RecurrentTrunkImpl::InitialState(int64_t rows) const {
  return at::zeros({rows, state_size()}, at::kFloat);
}

at::Tensor RecurrentTrunkImpl::Encode(const at::Tensor& observations) {
  at::Tensor inputs = NetworkInputs(spec_, observations);
  if (!conv_.is_empty()) return conv_->forward(inputs);
  if (!encoder_.is_empty()) return at::tanh(encoder_->forward(inputs));
  return inputs;
}

at::Tensor RecurrentTrunkImpl::Step(const at::Tensor& encoded,
                                    const at::Tensor& state) {
  if (core_ == Core::kGru) return gru_->forward(encoded, state);
  const std::tuple<at::Tensor, at::Tensor> next = lstm_->forward(
      encoded, std::make_tuple(state.narrow(1, 0, hidden_),
                               state.narrow(1, hidden_, hidden_)));
  return at::cat({std::get<0>(next), std::get<1>(next)}, 1);
}

at::Tensor RecurrentTrunkImpl::Hidden(const at::Tensor& state) const {
  return core_ == Core::kGru ? state : state.narrow(1, 0, hidden_);
}

at::Tensor RecurrentTrunkImpl::Unroll(const at::Tensor& observations,
                                      const at::Tensor& starts,
                                      const at::Tensor& state,
                                      at::Tensor* after) {
  const int64_t steps = starts.size(0);
  const int64_t rows = state.size(0);
  const at::Tensor encoded = Encode(observations).reshape({steps, rows, -1});
  // 1 where the state carries over, 0 where an episode starts.
  const at::Tensor keep = at::logical_not(starts).to(at::kFloat).unsqueeze(-1);
  std::vector<at::Tensor> features, states;
  at::Tensor current = state;
  for (int64_t t = 0; t < steps; ++t) {
    current = Step(encoded[t], current * keep[t]);
    features.push_back(Hidden(current));
    if (after != nullptr) states.push_back(current);
  }
  if (after != nullptr) *after = at::stack(states);
  return at::cat(features);
}

}  // namespace vantage
