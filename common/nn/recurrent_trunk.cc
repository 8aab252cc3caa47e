#include "common/nn/recurrent_trunk.h"

#include <ATen/ATen.h>
#include <torch/nn/init.h>

#include <algorithm>
#include <cmath>
#include <tuple>

#include "common/nn/networks.h"
#include "common/nn/recurrent_cell_kernel.h"

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

at::Tensor RecurrentTrunkImpl::UnrollWithoutGradients(
    const at::Tensor& observations, const at::Tensor& starts,
    const at::Tensor& state, at::Tensor* after) {
  at::NoGradGuard no_grad;
  const bool lstm = core_ == Core::kLstm;
  RecurrentCellKernel kernel =
      RecurrentCellKernel::Create(lstm ? RecurrentCellKernel::Kind::kLstm
                                       : RecurrentCellKernel::Kind::kGru,
                                  lstm ? lstm_->weight_ih : gru_->weight_ih,
                                  lstm ? lstm_->weight_hh : gru_->weight_hh,
                                  lstm ? lstm_->bias_ih : gru_->bias_ih,
                                  lstm ? lstm_->bias_hh : gru_->bias_hh)
          .value();
  const int64_t steps = starts.size(0);
  const int64_t rows = state.size(0);
  const int64_t width = state_size();
  const at::Tensor encoded = Encode(observations).to(at::kFloat).contiguous();
  const int64_t inputs = encoded.size(1);
  const at::Tensor begins = starts.to(at::kBool).contiguous();
  at::Tensor current = state.to(at::kFloat).contiguous().clone();
  at::Tensor states = at::empty({steps, rows, width}, at::kFloat);
  float* s = current.data_ptr<float>();
  for (int64_t t = 0; t < steps; ++t) {
    const bool* start = begins.data_ptr<bool>() + t * rows;
    for (int64_t r = 0; r < rows; ++r) {
      if (start[r]) std::fill(s + r * width, s + (r + 1) * width, 0.0f);
    }
    kernel.Step(encoded.data_ptr<float>() + t * rows * inputs, rows, s);
    std::copy(s, s + rows * width, states.data_ptr<float>() + t * rows * width);
  }
  if (after != nullptr) *after = states;
  return states.narrow(2, 0, hidden_).reshape({steps * rows, hidden_});
}

}  // namespace vantage
