#include "learner/algorithms/a2c/flat_rmsprop.h"

#include <ATen/ATen.h>
#include <torch/optim/rmsprop.h>

#include <algorithm>
#include <memory>
#include <string>
#include <utility>

#include "learner/algorithms/flat_optimizer_kernels.h"
#include "learner/algorithms/flat_optimizer_state.h"

namespace vantage {

using torch::optim::RMSpropOptions;
using torch::optim::RMSpropParamState;

FlatRmsprop::FlatRmsprop(std::vector<at::Tensor> parameters,
                         std::vector<int64_t> offsets, int64_t size,
                         RmspropArithmetic arithmetic)
    : parameters_(std::move(parameters)),
      offsets_(std::move(offsets)),
      arithmetic_(arithmetic),
      square_avg_(size, initial_square()) {}

float FlatRmsprop::initial_square() const {
  return arithmetic_ == RmspropArithmetic::kTensorflow ? 1.0f : 0.0f;
}

void FlatRmsprop::Step(const torch::optim::Optimizer& rmsprop,
                       float* parameters, const float* gradients) {
  const auto& options = static_cast<const RMSpropOptions&>(
      rmsprop.param_groups().front().options());
  ++step_;
  // The scalars in float and the operations in the order of LibTorch's
  // float kernels: mul_(alpha).addcmul_(g, g, 1 - alpha), then
  // addcdiv_(g, root, -lr), which computes p + (-lr * g) / root.
  const float alpha = static_cast<float>(options.alpha());
  const float one_minus_alpha = static_cast<float>(1.0 - options.alpha());
  const float eps = static_cast<float>(options.eps());
  const float minus_lr = static_cast<float>(-options.lr());
  RmspropKernel(alpha, one_minus_alpha, eps, minus_lr,
                arithmetic_ == RmspropArithmetic::kTensorflow,
                static_cast<int64_t>(square_avg_.size()), parameters, gradients,
                square_avg_.data());
}

void FlatRmsprop::StoreInto(torch::optim::Optimizer& rmsprop) const {
  auto& state = rmsprop.state();
  for (size_t i = 0; i < parameters_.size(); ++i) {
    const std::string key = OptimizerStateKey(parameters_[i]);
    if (step_ == 0) {
      state.erase(key);
      continue;
    }
    auto param_state = std::make_unique<RMSpropParamState>();
    param_state->step(step_);
    param_state->square_avg(
        FlatStateTensor(square_avg_, offsets_[i], parameters_[i]));
    state[key] = std::move(param_state);
  }
}

absl::Status FlatRmsprop::LoadFrom(const torch::optim::Optimizer& rmsprop) {
  const auto& state = rmsprop.state();
  int64_t step = -1;
  std::vector<float> square_avg(square_avg_.size(), initial_square());
  for (size_t i = 0; i < parameters_.size(); ++i) {
    const auto found = state.find(OptimizerStateKey(parameters_[i]));
    const auto* param_state =
        found == state.end()
            ? nullptr
            : static_cast<const RMSpropParamState*>(found->second.get());
    if (absl::Status status = CheckSameStep(
            param_state == nullptr ? 0 : param_state->step(), "RMSProp", step);
        !status.ok()) {
      return status;
    }
    if (param_state == nullptr) continue;
    if (absl::Status status =
            CopyStateToFlat(param_state->square_avg(), offsets_[i],
                            parameters_[i].numel(), square_avg, "RMSProp", i);
        !status.ok()) {
      return status;
    }
  }
  step_ = std::max<int64_t>(step, 0);
  square_avg_ = std::move(square_avg);
  return absl::OkStatus();
}

}  // namespace vantage
