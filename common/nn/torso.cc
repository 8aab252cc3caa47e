#include "common/nn/torso.h"

#include <ATen/ATen.h>
#include <torch/nn/init.h>
#include <torch/nn/modules/activation.h>
#include <torch/nn/modules/conv.h>
#include <torch/nn/modules/linear.h>

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace vantage {
namespace {

struct ConvLayer {
  int64_t channels;
  int64_t kernel;
  int64_t stride;
};

struct ConvDesign {
  Torso torso;
  const char* name;
  std::vector<ConvLayer> layers;
  int64_t dense;
};

const std::vector<ConvDesign>& Designs() {
  static const auto* designs = new std::vector<ConvDesign>{
      {Torso::kMinAtar, "minatar", {{16, 3, 1}}, 128},
      {Torso::kNature, "nature", {{32, 8, 4}, {64, 4, 2}, {64, 3, 1}}, 512},
  };
  return *designs;
}

const ConvDesign* FindDesign(Torso torso) {
  for (const ConvDesign& design : Designs()) {
    if (design.torso == torso) return &design;
  }
  return nullptr;
}

// The output side of a square input of `size` pixels after every layer
// (< 1: the input is too small).
int64_t OutputSide(const ConvDesign& design, int64_t size) {
  for (const ConvLayer& layer : design.layers) {
    if (size < layer.kernel) return 0;
    size = (size - layer.kernel) / layer.stride + 1;
  }
  return size;
}

// The smallest side the design takes.
int64_t SmallestSide(const ConvDesign& design) {
  int64_t side = 1;
  while (OutputSide(design, side) < 1) ++side;
  return side;
}

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

absl::StatusOr<Torso> ParseTorso(absl::string_view name) {
  if (name == "auto") return Torso::kAuto;
  if (name == "mlp") return Torso::kMlp;
  for (const ConvDesign& design : Designs()) {
    if (name == design.name) return design.torso;
  }
  return absl::InvalidArgumentError(absl::StrCat(
      "unknown torso \"", name, "\"; valid: auto, mlp, minatar, nature"));
}

std::string TorsoName(Torso torso) {
  if (torso == Torso::kAuto) return "auto";
  if (torso == Torso::kMlp) return "mlp";
  return FindDesign(torso)->name;
}

absl::StatusOr<Torso> ResolveTorso(Torso torso, const EnvSpec& spec) {
  const std::vector<int64_t>& shape = spec.observation_shape;
  if (torso == Torso::kAuto) {
    if (shape.size() != 3) return Torso::kMlp;
    const int64_t side = std::min(shape[1], shape[2]);
    return side >= SmallestSide(*FindDesign(Torso::kNature)) ? Torso::kNature
                                                             : Torso::kMinAtar;
  }
  if (torso == Torso::kMlp) return torso;
  const ConvDesign& design = *FindDesign(torso);
  if (shape.size() != 3) {
    return absl::InvalidArgumentError(absl::StrCat(
        "torso ", design.name, " needs image observations; ", spec.name,
        " has vectors of ", spec.observation_size, " (use --torso=mlp)"));
  }
  if (OutputSide(design, shape[1]) < 1 || OutputSide(design, shape[2]) < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "torso ", design.name, " needs frames of at least ",
        SmallestSide(design), "x", SmallestSide(design), " pixels; ", spec.name,
        " has ", absl::StrJoin(shape, "x"), " (use --torso=minatar)"));
  }
  return torso;
}

ConvTorsoImpl::ConvTorsoImpl(Torso torso, const std::vector<int64_t>& shape)
    : shape_(shape) {
  const ConvDesign& design = *FindDesign(torso);
  layers_ = register_module("layers", torch::nn::Sequential());
  int64_t channels = shape[0];
  for (const ConvLayer& layer : design.layers) {
    layers_->push_back(torch::nn::Conv2d(
        torch::nn::Conv2dOptions(channels, layer.channels, layer.kernel)
            .stride(layer.stride)));
    layers_->push_back(torch::nn::ReLU());
    channels = layer.channels;
  }
  layers_->push_back(torch::nn::Flatten());
  const int64_t flat =
      channels * OutputSide(design, shape[1]) * OutputSide(design, shape[2]);
  layers_->push_back(torch::nn::Linear(flat, design.dense));
  layers_->push_back(torch::nn::ReLU());
  features_ = design.dense;
  InitialiseOrthogonal(*this);
}

at::Tensor ConvTorsoImpl::forward(const at::Tensor& flat) {
  return layers_->forward(flat.reshape({-1, shape_[0], shape_[1], shape_[2]}));
}

}  // namespace vantage
