#ifndef VANTAGE_COMMON_NN_DICT_TORSO_H_
#define VANTAGE_COMMON_NN_DICT_TORSO_H_

// The torso of a Dict (or Tuple) observation (EnvSpec::observation_keys):
// each image entry through a convolutional torso of its own (minatar below
// 36 pixels a side, else nature, as --torso=auto picks for one image), the
// vector entries as they come (normalised before the networks), all
// features side by side for the MLP after it.

#include <torch/nn/module.h>

#include <cstdint>
#include <vector>

#include "common/env/environment.h"
#include "common/nn/torso.h"

namespace vantage {

class DictTorsoImpl : public torch::nn::Module {
 public:
  // `spec` has observation entries that CheckDictNetwork accepts.
  explicit DictTorsoImpl(const EnvSpec& spec);
  // [B, observation_size] as ObservationsForNetwork gives them (vectors
  // normalised, images divided by their high) -> [B, features()].
  at::Tensor forward(const at::Tensor& row);
  int64_t features() const { return features_; }

  // Each entry's convolutional torso (empty for a vector), in entry order.
  const std::vector<ConvTorso>& convs() const { return convs_; }
  const std::vector<ObservationKey>& keys() const { return keys_; }

 private:
  std::vector<ObservationKey> keys_;
  std::vector<ConvTorso> convs_;
  int64_t features_ = 0;
};
TORCH_MODULE(DictTorso);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_DICT_TORSO_H_
