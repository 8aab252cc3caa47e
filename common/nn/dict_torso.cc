#include "common/nn/dict_torso.h"

#include <ATen/ATen.h>

#include "absl/strings/str_cat.h"

namespace vantage {
DictTorsoImpl::DictTorsoImpl(const EnvSpec& spec)
    : keys_(spec.observation_keys) {
  for (size_t i = 0; i < keys_.size(); ++i) {
    const ObservationKey& key = keys_[i];
    if (!key.image()) {
      convs_.emplace_back(nullptr);
      features_ += key.size;
      continue;
    }
    convs_.push_back(register_module(
        absl::StrCat("conv", i),
        ConvTorso(DictImageTorso(spec, key).value(), key.shape)));
    features_ += convs_.back()->features();
  }
}

at::Tensor DictTorsoImpl::forward(const at::Tensor& row) {
  std::vector<at::Tensor> features;
  int64_t offset = 0;
  for (size_t i = 0; i < keys_.size(); ++i) {
    const at::Tensor part = row.slice(1, offset, offset + keys_[i].size);
    features.push_back(convs_[i].is_empty() ? part : convs_[i]->forward(part));
    offset += keys_[i].size;
  }
  return at::cat(features, 1);
}

}  // namespace vantage
