#ifndef VANTAGE_COMMON_NN_TORSO_H_
#define VANTAGE_COMMON_NN_TORSO_H_

// What the networks put between the observations and their output layer.
// Vectors go through a tanh MLP (NetworkConfig::hidden); images through a
// convolutional torso with ReLU, as in the published agents for them:
// - minatar: MinAtar's own net (Young & Tian 2019) for 10x10 grids: one
//   3x3 convolution of 16 channels, stride 1, then 128 units.
// - nature: the DQN net (Mnih et al. 2015): 32 8x8/4, 64 4x4/2, 64 3x3/1,
//   then 512 units; needs frames of at least 36 pixels a side.
// Convolutions and their dense layer are initialised orthogonally with gain
// sqrt(2) and zero biases, like the MLPs.

#include <torch/nn/module.h>
#include <torch/nn/modules/container/sequential.h>

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/env/environment.h"

namespace vantage {

enum class Torso {
  kAuto,  // mlp for vectors; minatar below 36 pixels a side, else nature
  kMlp,
  kMinAtar,
  kNature,
};

// "auto", "mlp", "minatar", "nature"; an unknown name lists them.
absl::StatusOr<Torso> ParseTorso(absl::string_view name);
std::string TorsoName(Torso torso);

// The torso networks for `spec` get (never kAuto), or why `torso` cannot
// take its observations (a convolution needs an observation_shape, nature
// at least 36x36).
absl::StatusOr<Torso> ResolveTorso(Torso torso, const EnvSpec& spec);

// Convolutions, flattening and one dense layer, all followed by ReLU:
// [B, C*H*W] (flat, as batches hold observations) -> [B, features()].
class ConvTorsoImpl : public torch::nn::Module {
 public:
  // `torso` is kMinAtar or kNature; `shape` is [C, H, W] and fits it
  // (ResolveTorso said so).
  ConvTorsoImpl(Torso torso, const std::vector<int64_t>& shape);
  at::Tensor forward(const at::Tensor& flat);
  int64_t features() const { return features_; }

 private:
  std::vector<int64_t> shape_;
  int64_t features_ = 0;
  torch::nn::Sequential layers_{nullptr};
};
TORCH_MODULE(ConvTorso);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_TORSO_H_
