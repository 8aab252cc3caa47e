#include "learner/algorithms/flat_adam.h"

#include <ATen/ATen.h>
#include <torch/optim/adam.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <utility>

#include "learner/algorithms/flat_optimizer_state.h"

namespace vantage {

FlatAdam::FlatAdam(std::vector<at::Tensor> parameters,
                   std::vector<int64_t> offsets, int64_t size)
    : parameters_(std::move(parameters)),
      offsets_(std::move(offsets)),
      exp_avg_(size, 0.0f),
      exp_avg_sq_(size, 0.0f) {}

void FlatAdam::Step(const torch::optim::Optimizer& adam, float* parameters,
                    const float* gradients) {
  const auto& options = static_cast<const torch::optim::AdamOptions&>(
      adam.param_groups().front().options());
  ++step_;
  const double beta1 = std::get<0>(options.betas());
  const double beta2 = std::get<1>(options.betas());
  const double bias_correction1 = 1.0 - std::pow(beta1, step_);
  const double bias_correction2 = 1.0 - std::pow(beta2, step_);
  // The scalars in float, as LibTorch's float kernels take them.
  const float b1 = static_cast<float>(beta1);
  const float b2 = static_cast<float>(beta2);
  const float one_minus_b1 = static_cast<float>(1.0 - beta1);
  const float one_minus_b2 = static_cast<float>(1.0 - beta2);
  const float correction2_sqrt =
      static_cast<float>(std::sqrt(bias_correction2));
  const float eps = static_cast<float>(options.eps());
  const float step_size = static_cast<float>(options.lr() / bias_correction1);
  const int64_t size = static_cast<int64_t>(exp_avg_.size());
  float* m = exp_avg_.data();
  float* v = exp_avg_sq_.data();
  for (int64_t i = 0; i < size; ++i) {
    const float g = gradients[i];
    m[i] = m[i] * b1 + one_minus_b1 * g;
    v[i] = v[i] * b2 + one_minus_b2 * g * g;
    const float denominator = std::sqrt(v[i]) / correction2_sqrt + eps;
    parameters[i] -= step_size * (m[i] / denominator);
  }
}

void FlatAdam::StoreInto(torch::optim::Optimizer& adam) const {
  auto& state = adam.state();
  for (size_t i = 0; i < parameters_.size(); ++i) {
    const std::string key = OptimizerStateKey(parameters_[i]);
    if (step_ == 0) {
      state.erase(key);
      continue;
    }
    auto param_state = std::make_unique<torch::optim::AdamParamState>();
    param_state->step(step_);
    param_state->exp_avg(
        FlatStateTensor(exp_avg_, offsets_[i], parameters_[i]));
    param_state->exp_avg_sq(
        FlatStateTensor(exp_avg_sq_, offsets_[i], parameters_[i]));
    state[key] = std::move(param_state);
  }
}

absl::Status FlatAdam::LoadFrom(const torch::optim::Optimizer& adam) {
  const auto& state = adam.state();
  int64_t step = -1;
  std::vector<float> exp_avg(exp_avg_.size(), 0.0f);
  std::vector<float> exp_avg_sq(exp_avg_sq_.size(), 0.0f);
  for (size_t i = 0; i < parameters_.size(); ++i) {
    const auto found = state.find(OptimizerStateKey(parameters_[i]));
    const auto* param_state =
        found == state.end() ? nullptr
                             : static_cast<const torch::optim::AdamParamState*>(
                                   found->second.get());
    if (absl::Status status = CheckSameStep(
            param_state == nullptr ? 0 : param_state->step(), "Adam", step);
        !status.ok()) {
      return status;
    }
    if (param_state == nullptr) continue;
    for (auto [source, target] :
         {std::pair{&param_state->exp_avg(), &exp_avg},
          std::pair{&param_state->exp_avg_sq(), &exp_avg_sq}}) {
      if (absl::Status status = CopyStateToFlat(
              *source, offsets_[i], parameters_[i].numel(), *target, "Adam", i);
          !status.ok()) {
        return status;
      }
    }
  }
  step_ = std::max<int64_t>(step, 0);
  exp_avg_ = std::move(exp_avg);
  exp_avg_sq_ = std::move(exp_avg_sq);
  return absl::OkStatus();
}

}  // namespace vantage
