#ifndef VANTAGE_COMMON_NN_NETWORK_CONFIG_H_
#define VANTAGE_COMMON_NN_NETWORK_CONFIG_H_

// What networks a run builds, without LibTorch: the run configuration, the
// command line and the checks read this, and only the code that builds the
// networks (common/nn/networks.h, torso.h) needs the module API.
//
// Vectors go through a tanh MLP (NetworkConfig::hidden); images through a
// convolutional torso with ReLU, as in the published agents for them:
// - minatar: MinAtar's own net (Young & Tian 2019) for 10x10 grids: one
//   3x3 convolution of 16 channels, stride 1, then 128 units.
// - nature: the DQN net (Mnih et al. 2015): 32 8x8/4, 64 4x4/2, 64 3x3/1,
//   then 512 units; needs frames of at least 36 pixels a side.

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
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

// The layers of a convolutional torso (kMinAtar, kNature).
struct ConvLayerDesign {
  int64_t channels;
  int64_t kernel;
  int64_t stride;
};
struct ConvTorsoDesign {
  Torso torso;
  const char* name;
  std::vector<ConvLayerDesign> layers;
  int64_t dense;  // units of the dense layer after the convolutions
};
// Null for kAuto and kMlp.
const ConvTorsoDesign* FindConvTorsoDesign(Torso torso);
// The output side of a square input of `size` pixels after every layer
// (< 1: the input is too small).
int64_t ConvOutputSide(const ConvTorsoDesign& design, int64_t size);

struct NetworkConfig {
  std::vector<int64_t> hidden = {64, 64};  // the MLP torso's layers
  Torso torso = Torso::kAuto;
  // The value network uses the policy's convolutions instead of its own, so
  // that one trunk learns from both losses. Needs a convolutional torso,
  // and an algorithm that steps both networks with one optimiser.
  bool shared_torso = false;
};

// Why `config` cannot build networks for `spec`: a torso that does not fit
// (ResolveTorso), or a shared torso that resolves to the MLP.
absl::Status CheckNetworkConfig(const NetworkConfig& config,
                                const EnvSpec& spec);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_NETWORK_CONFIG_H_
