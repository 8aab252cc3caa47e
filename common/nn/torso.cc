#include "common/nn/torso.h"

#include <ATen/ATen.h>
#include <torch/nn/init.h>
#include <torch/nn/modules/activation.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/modules/linear.h>

#include <cmath>

namespace vantage {
namespace {

void InitialiseOrthogonal(torch::nn::Module& module) {
  for (auto& named : module.named_parameters(/*recurse=*/true)) {
    at::Tensor& parameter = named.value();
    if (parameter.dim() >= 2) {
      torch::nn::init::orthogonal_(parameter, std::sqrt(2.0));
    } else {
      torch::nn::init::zeros_(parameter);
    }
  }
}

}  // namespace

ConvTorsoImpl::ConvTorsoImpl(Torso torso, const std::vector<int64_t>& shape)
    : shape_(shape) {
  const ConvTorsoDesign& design = *FindConvTorsoDesign(torso);
  layers_ = register_module("layers", torch::nn::Sequential());
  int64_t channels = shape[0];
  for (const ConvLayerDesign& layer : design.layers) {
    layers_->push_back(torch::nn::Conv2d(
        torch::nn::Conv2dOptions(channels, layer.channels, layer.kernel)
            .stride(layer.stride)));
    layers_->push_back(torch::nn::ReLU());
    channels = layer.channels;
  }
  layers_->push_back(torch::nn::Flatten());
  const int64_t flat = channels * ConvOutputSide(design, shape[1]) *
                       ConvOutputSide(design, shape[2]);
  layers_->push_back(torch::nn::Linear(flat, design.dense));
  layers_->push_back(torch::nn::ReLU());
  features_ = design.dense;
  InitialiseOrthogonal(*this);
}

at::Tensor ConvTorsoImpl::forward(const at::Tensor& flat) {
  return layers_->forward(flat.reshape({-1, shape_[0], shape_[1], shape_[2]}));
}

}  // namespace vantage
