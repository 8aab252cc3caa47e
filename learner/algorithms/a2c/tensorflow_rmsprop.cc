#include "learner/algorithms/a2c/tensorflow_rmsprop.h"

#include <ATen/ATen.h>
#include <c10/util/irange.h>
#include <torch/optim/serialize.h>

#include <memory>
#include <utility>

namespace vantage {

using torch::optim::RMSpropOptions;
using torch::optim::RMSpropParamState;

TensorflowRmsprop::TensorflowRmsprop(std::vector<at::Tensor> parameters,
                                     const RMSpropOptions& options)
    : Optimizer({torch::optim::OptimizerParamGroup(std::move(parameters))},
                std::make_unique<RMSpropOptions>(options)) {
  TORCH_CHECK(options.lr() >= 0, "invalid learning rate ", options.lr());
  TORCH_CHECK(options.alpha() > 0 && options.alpha() < 1, "invalid alpha ",
              options.alpha());
  TORCH_CHECK(options.eps() >= 0, "invalid eps ", options.eps());
  TORCH_CHECK(options.momentum() == 0 && !options.centered() &&
                  options.weight_decay() == 0,
              "TensorflowRmsprop has no momentum, centring or weight decay");
}

at::Tensor TensorflowRmsprop::step(LossClosure closure) {
  at::NoGradGuard no_grad;
  at::Tensor loss;
  if (closure != nullptr) {
    at::AutoGradMode enable_grad(true);
    loss = closure();
  }
  for (auto& group : param_groups_) {
    const auto& options = static_cast<const RMSpropOptions&>(group.options());
    for (at::Tensor& parameter : group.params()) {
      if (!parameter.grad().defined()) continue;
      const at::Tensor& grad = parameter.grad();
      auto key = c10::guts::to_string(parameter.unsafeGetTensorImpl());
      auto found = state_.find(key);
      if (found == state_.end()) {
        auto state = std::make_unique<RMSpropParamState>();
        state->square_avg(at::ones_like(parameter, at::MemoryFormat::Preserve));
        found = state_.emplace(key, std::move(state)).first;
      }
      auto& state = static_cast<RMSpropParamState&>(*found->second);
      state.step(state.step() + 1);
      at::Tensor& square_avg = state.square_avg();
      square_avg.mul_(options.alpha())
          .addcmul_(grad, grad, 1 - options.alpha());
      parameter.addcdiv_(grad, (square_avg + options.eps()).sqrt_(),
                         -options.lr());
    }
  }
  return loss;
}

void TensorflowRmsprop::save(torch::serialize::OutputArchive& archive) const {
  torch::optim::serialize<RMSpropParamState, RMSpropOptions>(archive, *this);
}

void TensorflowRmsprop::load(torch::serialize::InputArchive& archive) {
  torch::optim::serialize<RMSpropParamState, RMSpropOptions>(archive, *this);
}

}  // namespace vantage
