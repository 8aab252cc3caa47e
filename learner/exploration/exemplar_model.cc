#include "learner/exploration/exemplar_model.h"

#include <ATen/ATen.h>
#include <torch/nn/init.h>
#include <torch/nn/modules/linear.h>

namespace vantage {

GlorotMlpImpl::GlorotMlpImpl(int64_t inputs, const std::vector<int64_t>& sizes,
                             bool linear_output)
    : linear_output_(linear_output) {
  layers_ = register_module("layers", torch::nn::ModuleList());
  int64_t width = inputs;
  for (int64_t size : sizes) {
    torch::nn::Linear layer(width, size);
    torch::nn::init::xavier_uniform_(layer->weight);
    torch::nn::init::zeros_(layer->bias);
    layers_->push_back(layer);
    width = size;
  }
}

at::Tensor GlorotMlpImpl::forward(const at::Tensor& x) {
  at::Tensor h = x;
  for (size_t i = 0; i < layers_->size(); ++i) {
    h = layers_->ptr<torch::nn::LinearImpl>(i)->forward(h);
    if (!linear_output_ || i + 1 < layers_->size()) h = at::tanh(h);
  }
  return h;
}

namespace {

std::vector<int64_t> Then(std::vector<int64_t> sizes, int64_t last) {
  sizes.push_back(last);
  return sizes;
}

}  // namespace

// The reference code's layout: a tanh trunk of the hidden sizes and one
// more layer as wide as the first, then mean and log-variance heads that
// each repeat the hidden sizes before a linear output.
ExemplarEncoderImpl::ExemplarEncoderImpl(int64_t inputs,
                                         const Ex2Config& config) {
  const int64_t width = config.hidden.front();
  trunk_ = register_module(
      "trunk", GlorotMlp(inputs, Then(config.hidden, width), false));
  mean_ = register_module(
      "mean", GlorotMlp(width, Then(config.hidden, config.feature_dim), true));
  log_variance_ = register_module(
      "log_variance",
      GlorotMlp(width, Then(config.hidden, config.feature_dim), true));
}

std::pair<at::Tensor, at::Tensor> ExemplarEncoderImpl::forward(
    const at::Tensor& x) {
  const at::Tensor h = trunk_->forward(x);
  return {mean_->forward(h), log_variance_->forward(h)};
}

ExemplarModelImpl::ExemplarModelImpl(int64_t inputs, const Ex2Config& config)
    : inputs_(inputs) {
  exemplar_encoder_ =
      register_module("exemplar_encoder", ExemplarEncoder(inputs, config));
  candidate_encoder_ =
      register_module("candidate_encoder", ExemplarEncoder(inputs, config));
  discriminator_ = register_module(
      "discriminator",
      GlorotMlp(2 * config.feature_dim, Then(config.hidden, 1), true));
}

ExemplarOutput ExemplarModelImpl::forward(const at::Tensor& exemplars,
                                          const at::Tensor& candidates,
                                          const at::Generator* noise) {
  const auto [mean1, log_var1] = exemplar_encoder_->forward(exemplars);
  const auto [mean2, log_var2] = candidate_encoder_->forward(candidates);
  const auto sample = [&](const at::Tensor& mean, const at::Tensor& log_var) {
    if (noise == nullptr) return mean;
    return mean + at::exp(0.5 * log_var) *
                      at::randn(mean.sizes(), *noise, mean.options());
  };
  const at::Tensor latents =
      at::cat({sample(mean1, log_var1), sample(mean2, log_var2)}, 1);
  const auto kl = [](const at::Tensor& mean, const at::Tensor& log_var) {
    return -0.5 * (1 + log_var - mean.pow(2) - at::exp(log_var)).sum(1);
  };
  ExemplarOutput output;
  output.probability =
      at::sigmoid(discriminator_->forward(latents)).reshape({-1});
  output.kl = kl(mean1, log_var1) + kl(mean2, log_var2);
  return output;
}

ExemplarLoss ComputeExemplarLoss(ExemplarModelImpl& model,
                                 const at::Tensor& positives,
                                 const at::Tensor& negatives, double kl_weight,
                                 const at::Generator& noise) {
  const int64_t b = positives.size(0);
  const at::Tensor exemplars = at::cat({positives, positives});
  const at::Tensor candidates = at::cat({positives, negatives});
  const at::Tensor labels =
      at::cat({at::ones({b}, positives.options()),
               at::zeros({negatives.size(0)}, positives.options())});
  const ExemplarOutput out = model.forward(exemplars, candidates, &noise);
  const at::Tensor d = out.probability.clamp(1e-6, 1 - 1e-6);
  const at::Tensor log_likelihood =
      labels * at::log(d) + (1 - labels) * at::log(1 - d);
  ExemplarLoss result;
  result.loss = -(log_likelihood - kl_weight * out.kl).mean();
  result.accuracy = ((out.probability.detach() > 0.5) == (labels > 0.5))
                        .to(at::kDouble)
                        .mean()
                        .item<double>();
  return result;
}

at::Tensor NoveltyBonus(ExemplarModelImpl& model, const at::Tensor& x) {
  at::NoGradGuard no_grad;
  const at::Tensor d =
      model.forward(x, x, nullptr).probability.clamp(1e-5, 1 - 1e-5);
  return at::log(d / (1 - d));
}

}  // namespace vantage
