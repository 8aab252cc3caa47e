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
// - ex2doom: the policy of EX2's first-person-maze run (Fu et al. 2017's
//   code, exps/doom.py): 16 4x4/4, 16 4x4/4, then 32 units; frames of at
//   least 16 pixels a side.

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
  kEx2Doom,
};

// "auto", "mlp", "minatar", "nature", "ex2doom"; an unknown name lists
// them (TorsoNames).
absl::StatusOr<Torso> ParseTorso(absl::string_view name);
std::string TorsoName(Torso torso);
// Every name ParseTorso takes, comma-separated.
std::string TorsoNames();

// The torso networks for `spec` get (never kAuto), or why `torso` cannot
// take its observations (a convolution needs an observation_shape, nature
// at least 36x36).
absl::StatusOr<Torso> ResolveTorso(Torso torso, const EnvSpec& spec);

// The layers of a convolutional torso (every torso but kAuto and kMlp).
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

// A recurrent core after the torso: the policy then acts on what it has
// seen in its episode so far, not only on the current observation.
enum class Core {
  kNone,
  kGru,
  kLstm,
};

// "none", "gru", "lstm"; an unknown name lists them.
absl::StatusOr<Core> ParseCore(absl::string_view name);
std::string CoreName(Core core);

struct NetworkConfig {
  std::vector<int64_t> hidden = {64, 64};  // the MLP torso's layers
  Torso torso = Torso::kAuto;
  // With a core, the torso (tanh after every --hidden layer, or the
  // convolutions) feeds a GRU or LSTM of core_size units, and the policy's
  // and the value's output layers both read its hidden state: one trunk for
  // both, since the actor carries only the policy's state and a separate
  // value core would start every rollout from a state nobody computed.
  Core core = Core::kNone;
  int64_t core_size = 64;
  // Backpropagation through time over chunks of seq_len steps (0: whole
  // segments); each chunk starts from the state the core had there.
  int64_t seq_len = 0;
  // The value network uses the policy's convolutions instead of its own, so
  // that one trunk learns from both losses. Needs a convolutional torso,
  // and an algorithm that steps both networks with one optimiser.
  bool shared_torso = false;

  bool recurrent() const { return core != Core::kNone; }
  // Floats per environment of the core's state: the GRU's hidden state, or
  // the LSTM's hidden and cell states one after the other; 0 without one.
  int64_t core_state_size() const {
    if (core == Core::kNone) return 0;
    return core == Core::kLstm ? 2 * core_size : core_size;
  }
};

// Why `config` cannot build networks for `spec`: a torso that does not fit
// (ResolveTorso), a shared torso that resolves to the MLP, or a core of
// fewer than one unit.
absl::Status CheckNetworkConfig(const NetworkConfig& config,
                                const EnvSpec& spec);

// Dict observations (EnvSpec::observation_keys, common/nn/dict_torso.h):
// why a network cannot take `spec`'s with `config` (a torso other than
// auto, a shared torso, a recurrent core, or an image too small for any
// convolutional torso); OK for a spec without entries.
absl::Status CheckDictNetwork(const NetworkConfig& config, const EnvSpec& spec);
// The convolutional torso an image entry gets: --torso=auto's choice for
// that image alone.
absl::StatusOr<Torso> DictImageTorso(const EnvSpec& spec,
                                     const ObservationKey& key);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_NETWORK_CONFIG_H_
