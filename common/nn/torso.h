#ifndef VANTAGE_COMMON_NN_TORSO_H_
#define VANTAGE_COMMON_NN_TORSO_H_

// What the networks put between the observations and their output layer:
// the convolutional torsos that common/nn/network_config.h describes.
// Convolutions and their dense layer are initialised orthogonally with gain
// sqrt(2) and zero biases, like the MLPs.

#include <torch/nn/module.h>
#include <torch/nn/modules/container/sequential.h>

#include <cstdint>
#include <vector>

#include "common/nn/network_config.h"

namespace vantage {

// Convolutions, flattening and one dense layer, all followed by ReLU:
// [B, C*H*W] (flat, as batches hold observations) -> [B, features()].
class ConvTorsoImpl : public torch::nn::Module {
 public:
  // `torso` is a convolutional one; `shape` is [C, H, W] and fits it
  // (ResolveTorso said so).
  ConvTorsoImpl(Torso torso, const std::vector<int64_t>& shape);
  at::Tensor forward(const at::Tensor& flat);
  int64_t features() const { return features_; }
  // Its layers in order (for code that writes them elsewhere).
  const torch::nn::Sequential& layers() const { return layers_; }

 private:
  std::vector<int64_t> shape_;
  int64_t features_ = 0;
  torch::nn::Sequential layers_{nullptr};
};
TORCH_MODULE(ConvTorso);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_TORSO_H_
