#include "bench/bare_ppo.h"

#include <ATen/ATen.h>
#include <torch/nn/modules/activation.h>
#include <torch/nn/modules/linear.h>

#include <cmath>

namespace vantage {
namespace {

torch::nn::Sequential BareMlp(const BarePpoShape& shape, int64_t outputs) {
  torch::nn::Sequential mlp;
  int64_t inputs = shape.observations;
  for (int64_t width : shape.hidden) {
    mlp->push_back(torch::nn::Linear(inputs, width));
    mlp->push_back(torch::nn::Tanh());
    inputs = width;
  }
  mlp->push_back(torch::nn::Linear(inputs, outputs));
  return mlp;
}

}  // namespace

BarePpo::BarePpo(const BarePpoShape& shape)
    : shape_(shape),
      policy_(BareMlp(shape, shape.actions)),
      value_(BareMlp(shape, 1)),
      log_std_(at::zeros({shape.actions}).set_requires_grad(true)) {
  std::vector<at::Tensor> parameters = policy_->parameters();
  for (const at::Tensor& p : value_->parameters()) parameters.push_back(p);
  parameters.push_back(log_std_);
  optimizer_ = std::make_unique<torch::optim::Adam>(
      parameters, torch::optim::AdamOptions(3e-4).eps(1e-5));
}

void BarePpo::Update(const UpdateBatch& batch) {
  const int64_t size = batch.observations.size(0);
  const int64_t minibatch = std::max<int64_t>(1, size / shape_.minibatches);
  for (int epoch = 0; epoch < shape_.epochs; ++epoch) {
    const at::Tensor permutation = at::randperm(size, at::kLong);
    for (int64_t begin = 0; begin + minibatch <= size; begin += minibatch) {
      const at::Tensor index = permutation.slice(0, begin, begin + minibatch);
      const at::Tensor obs = batch.observations.index_select(0, index);
      const at::Tensor actions = batch.actions.index_select(0, index);
      const at::Tensor mean = policy_->forward(obs);
      const at::Tensor z = (actions - mean) * at::exp(-log_std_);
      const at::Tensor log_prob = (-0.5 * z * z - log_std_).sum(-1) -
                                  0.5 * shape_.actions * std::log(2 * M_PI);
      const at::Tensor ratio =
          at::exp(log_prob - batch.behaviour_log_probs.index_select(0, index));
      const at::Tensor adv = batch.advantages.index_select(0, index);
      const at::Tensor policy_loss =
          -at::min(ratio * adv, ratio.clamp(0.8, 1.2) * adv).mean();
      const at::Tensor error = value_->forward(obs).squeeze(-1) -
                               batch.returns.index_select(0, index);
      const at::Tensor loss = policy_loss + 0.5 * 0.5 * (error * error).mean();
      optimizer_->zero_grad();
      loss.backward();
      optimizer_->step();
    }
  }
}

EnvSpec BenchSpec(const BarePpoShape& shape) {
  EnvSpec spec;
  spec.name = "HalfCheetah";
  spec.observation_size = shape.observations;
  spec.action_size = shape.actions;
  spec.action_low.assign(shape.actions, -1.0);
  spec.action_high.assign(shape.actions, 1.0);
  return spec;
}

UpdateBatch SyntheticBatch(const BarePpoShape& shape, int64_t samples) {
  UpdateBatch batch;
  batch.horizon = samples;
  batch.streams = 1;
  batch.observations = at::randn({samples, shape.observations});
  batch.actions = at::randn({samples, shape.actions}).clamp(-1, 1);
  batch.behaviour_log_probs = at::randn({samples}) - 6;
  batch.advantages = at::randn({samples});
  batch.returns = at::randn({samples});
  return batch;
}

}  // namespace vantage
