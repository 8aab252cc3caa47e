#include "learner/algorithms/flat_adam.h"

#include <ATen/ATen.h>
#include <torch/optim/adam.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <utility>

#include "learner/algorithms/flat_optimizer_kernels.h"
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
  AdamCoefficients coefficients;
  coefficients.beta1 = static_cast<float>(beta1);
  coefficients.beta2 = static_cast<float>(beta2);
  coefficients.one_minus_beta1 = static_cast<float>(1.0 - beta1);
  coefficients.one_minus_beta2 = static_cast<float>(1.0 - beta2);
  coefficients.correction2_sqrt =
      static_cast<float>(std::sqrt(bias_correction2));
  coefficients.eps = static_cast<float>(options.eps());
  coefficients.step_size = static_cast<float>(options.lr() / bias_correction1);
  AdamKernel(coefficients, static_cast<int64_t>(exp_avg_.size()), parameters,
             gradients, exp_avg_.data(), exp_avg_sq_.data());
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
