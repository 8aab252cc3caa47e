#include "common/nn/tanh_mlp.h"

#include <ATen/ATen.h>
#include <torch/nn/init.h>

#include <cmath>

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

}  // namespace vantage
