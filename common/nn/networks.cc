#include "common/nn/networks.h"

#include <ATen/ATen.h>
#include <torch/nn/init.h>

#include <cmath>
#include <string>

#include "common/nn/distributions.h"

namespace vantage {

TanhMlpImpl::TanhMlpImpl(int64_t inputs, const std::vector<int64_t>& hidden,
                         int64_t outputs, double output_gain) {
  layers_ = register_module("layers", torch::nn::ModuleList());
  int64_t width = inputs;
  std::vector<int64_t> sizes = hidden;
  sizes.push_back(outputs);
  for (size_t i = 0; i < sizes.size(); ++i) {
    torch::nn::Linear layer(width, sizes[i]);
    const bool last = i + 1 == sizes.size();
    torch::nn::init::orthogonal_(layer->weight,
                                 last ? output_gain : std::sqrt(2.0));
    torch::nn::init::zeros_(layer->bias);
    layers_->push_back(layer);
    width = sizes[i];
  }
}

at::Tensor TanhMlpImpl::forward(const at::Tensor& x) {
  at::Tensor h = x;
  for (size_t i = 0; i < layers_->size(); ++i) {
    h = layers_->ptr<torch::nn::LinearImpl>(i)->forward(h);
    if (i + 1 < layers_->size()) h = at::tanh(h);
  }
  return h;
}

PolicyNetworkImpl::PolicyNetworkImpl(const EnvSpec& spec,
                                     const NetworkConfig& config)
    : discrete_(spec.discrete) {
  body_ = register_module(
      "body", TanhMlp(spec.observation_size, config.hidden, spec.action_size,
                      /*output_gain=*/0.01));
  if (!discrete_) {
    log_std_ = register_parameter("log_std", at::zeros({spec.action_size}));
  }
}

at::Tensor PolicyNetworkImpl::forward(const at::Tensor& observations) {
  return body_->forward(observations);
}

at::Tensor PolicyNetworkImpl::LogProb(const at::Tensor& output,
                                      const at::Tensor& actions) {
  if (discrete_) return CategoricalLogProb(output, actions.reshape({-1}));
  return DiagGaussianLogProb(output, log_std_, actions);
}

at::Tensor PolicyNetworkImpl::Entropy(const at::Tensor& output) {
  if (discrete_) return CategoricalEntropy(output);
  return DiagGaussianEntropy(output, log_std_);
}

at::Tensor PolicyNetworkImpl::Kl(const at::Tensor& old_output,
                                 const at::Tensor& old_log_std,
                                 const at::Tensor& output) {
  if (discrete_) return CategoricalKl(old_output, output);
  return DiagGaussianKl(old_output, old_log_std, output, log_std_);
}

at::Tensor PolicyNetworkImpl::Act(const at::Tensor& output, bool deterministic,
                                  at::Generator generator) {
  if (discrete_) {
    const at::Tensor index =
        deterministic
            ? output.argmax(-1)
            : at::multinomial(at::softmax(output, -1), 1, false, generator)
                  .squeeze(-1);
    return index.to(output.scalar_type()).unsqueeze(-1);
  }
  if (deterministic) return output;
  return output + at::exp(log_std_) * at::normal(0.0, 1.0, output.sizes(),
                                                 generator, output.options());
}

ValueNetworkImpl::ValueNetworkImpl(int64_t observation_size,
                                   const NetworkConfig& config) {
  body_ = register_module(
      "body", TanhMlp(observation_size, config.hidden, 1, /*output_gain=*/1.0));
}

at::Tensor ValueNetworkImpl::forward(const at::Tensor& observations) {
  return body_->forward(observations).squeeze(-1);
}

}  // namespace vantage
