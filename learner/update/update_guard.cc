#include "learner/update/update_guard.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <torch/serialize/archive.h>

#include <cmath>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "common/nn/networks.h"
#include "learner/batch/reward_scaler.h"
#include "learner/exploration/ex2_bonus.h"

namespace vantage {
namespace {

template <typename Saver>
std::string SaveToBytes(Saver save) {
  torch::serialize::OutputArchive archive;
  save(archive);
  std::ostringstream bytes;
  archive.save_to(bytes);
  return bytes.str();
}

}  // namespace

UpdateGuard::UpdateGuard(PolicyNetworkImpl& policy, ValueNetworkImpl& value,
                         PolicyUpdater& updater, RewardScaler* reward_scaler,
                         Ex2Bonus* exploration)
    : policy_(policy),
      value_(value),
      updater_(updater),
      reward_scaler_(reward_scaler),
      exploration_(exploration) {
  for (const at::Tensor& p : NetworkParameters(policy_, value_)) {
    parameters_.push_back(p.detach().clone());
  }
  // The optimisers' state is reached only through their archives.
  updater_state_ = SaveToBytes(
      [&](torch::serialize::OutputArchive& a) { updater_.Save(a); });
  if (reward_scaler_ != nullptr) {
    reward_scaler_state_ = SaveToBytes(
        [&](torch::serialize::OutputArchive& a) { reward_scaler_->Save(a); });
  }
  if (exploration_ != nullptr) {
    exploration_state_ = SaveToBytes([&](torch::serialize::OutputArchive& a) {
      exploration_->SaveModelState(a, "ex2");
    });
  }
}

std::string UpdateGuard::Fault(const AlgorithmStats& stats,
                               double max_gradient_norm) const {
  if (!std::isfinite(stats.policy_loss) || !std::isfinite(stats.value_loss)) {
    return absl::StrCat("non-finite loss: policy ", stats.policy_loss,
                        ", value ", stats.value_loss);
  }
  if (stats.max_gradient_norm > max_gradient_norm) {
    return absl::StrCat("gradient norm ", stats.max_gradient_norm,
                        " above the limit of ", max_gradient_norm);
  }
  for (const auto& item : policy_.named_parameters()) {
    if (!at::isfinite(item.value()).all().item<bool>()) {
      return absl::StrCat("non-finite policy parameter ", item.key());
    }
  }
  for (const auto& item : value_.named_parameters()) {
    if (!at::isfinite(item.value()).all().item<bool>()) {
      return absl::StrCat("non-finite value parameter ", item.key());
    }
  }
  if (exploration_ != nullptr) {
    for (const auto& item : exploration_->model().named_parameters()) {
      if (!at::isfinite(item.value()).all().item<bool>()) {
        return absl::StrCat("non-finite exploration model parameter ",
                            item.key());
      }
    }
  }
  return "";
}

void UpdateGuard::Restore() {
  {
    at::NoGradGuard no_grad;
    std::vector<at::Tensor> parameters = NetworkParameters(policy_, value_);
    for (size_t i = 0; i < parameters.size(); ++i) {
      parameters[i].copy_(parameters_[i]);
    }
  }
  // The state was saved by these very objects, so failing to load it back
  // is a programmer error.
  torch::serialize::InputArchive updater;
  std::istringstream updater_bytes(updater_state_);
  updater.load_from(updater_bytes);
  const absl::Status loaded = updater_.Load(updater);
  TORCH_CHECK(loaded.ok(), "rollback: ", loaded.ToString());
  if (reward_scaler_ != nullptr) {
    torch::serialize::InputArchive scaler;
    std::istringstream scaler_bytes(reward_scaler_state_);
    scaler.load_from(scaler_bytes);
    const absl::Status scaler_loaded = reward_scaler_->Load(scaler);
    TORCH_CHECK(scaler_loaded.ok(), "rollback: ", scaler_loaded.ToString());
  }
  if (exploration_ != nullptr) {
    torch::serialize::InputArchive exploration;
    std::istringstream exploration_bytes(exploration_state_);
    exploration.load_from(exploration_bytes);
    const absl::Status exploration_loaded =
        exploration_->LoadModelState(exploration, "ex2");
    TORCH_CHECK(exploration_loaded.ok(),
                "rollback: ", exploration_loaded.ToString());
  }
}

}  // namespace vantage
