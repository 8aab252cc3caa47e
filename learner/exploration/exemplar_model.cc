#include "learner/exploration/exemplar_model.h"

#include <ATen/ATen.h>
#include <torch/nn/init.h>
#include <torch/nn/modules/conv.h>
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

Ex2ConvTrunkImpl::Ex2ConvTrunkImpl(const std::vector<int64_t>& image_shape)
    : image_shape_(image_shape) {
  TORCH_CHECK(image_shape.size() == 3, "EX2's ConvNet takes [C, H, W] images");
  constexpr int64_t kFilters = 16, kSize = 4, kStride = 2, kPadding = 3;
  layers_ = register_module("layers", torch::nn::ModuleList());
  int64_t channels = image_shape[0], height = image_shape[1],
          width = image_shape[2];
  for (int i = 0; i < 2; ++i) {
    torch::nn::Conv2d conv(torch::nn::Conv2dOptions(channels, kFilters, kSize)
                               .stride(kStride)
                               .padding(kPadding));
    torch::nn::init::xavier_uniform_(conv->weight);
    torch::nn::init::zeros_(conv->bias);
    layers_->push_back(conv);
    channels = kFilters;
    height = (height + 2 * kPadding - kSize) / kStride + 1;
    width = (width + 2 * kPadding - kSize) / kStride + 1;
  }
  features_ = channels * height * width;
}

at::Tensor Ex2ConvTrunkImpl::forward(const at::Tensor& images) {
  at::Tensor h = images.reshape(
      {images.size(0), image_shape_[0], image_shape_[1], image_shape_[2]});
  for (size_t i = 0; i < layers_->size(); ++i) {
    h = at::tanh(layers_->ptr<torch::nn::Conv2dImpl>(i)->forward(h));
  }
  return h.flatten(1);
}

// The reference code's layout: a tanh trunk of the hidden sizes and one
// more layer as wide as the first (or the ConvNet), then mean and
// log-variance heads that each repeat the hidden sizes before a linear
// output.
ExemplarEncoderImpl::ExemplarEncoderImpl(
    int64_t inputs, const Ex2Config& config,
    const std::vector<int64_t>& image_shape) {
  int64_t width = config.hidden.front();
  if (config.convolutional()) {
    conv_ = register_module("conv", Ex2ConvTrunk(image_shape));
    image_size_ = image_shape[0] * image_shape[1] * image_shape[2];
    width = conv_->features() + (inputs - image_size_);
  } else {
    trunk_ = register_module(
        "trunk", GlorotMlp(inputs, Then(config.hidden, width), false));
  }
  mean_ = register_module(
      "mean", GlorotMlp(width, Then(config.hidden, config.feature_dim), true));
  log_variance_ = register_module(
      "log_variance",
      GlorotMlp(width, Then(config.hidden, config.feature_dim), true));
}

std::pair<at::Tensor, at::Tensor> ExemplarEncoderImpl::forward(
    const at::Tensor& x) {
  at::Tensor h;
  if (conv_.is_empty()) {
    h = trunk_->forward(x);
  } else {
    h = conv_->forward(x.narrow(1, 0, image_size_));
    if (x.size(1) > image_size_) {
      h = at::cat({h, x.narrow(1, image_size_, x.size(1) - image_size_)}, 1);
    }
  }
  return {mean_->forward(h), log_variance_->forward(h)};
}

ExemplarModelImpl::ExemplarModelImpl(int64_t inputs, const Ex2Config& config,
                                     const std::vector<int64_t>& image_shape)
    : inputs_(inputs), convolutional_(config.convolutional()) {
  exemplar_encoder_ = register_module(
      "exemplar_encoder", ExemplarEncoder(inputs, config, image_shape));
  candidate_encoder_ = register_module(
      "candidate_encoder", ExemplarEncoder(inputs, config, image_shape));
  discriminator_ = register_module(
      "discriminator",
      GlorotMlp(2 * config.feature_dim, Then(config.hidden, 1), true));
}

ExemplarOutput ExemplarModelImpl::forward(const at::Tensor& exemplars,
                                          const at::Tensor& candidates,
                                          const at::Generator* noise) {
  return Discriminate(exemplar_encoder_->forward(exemplars),
                      candidate_encoder_->forward(candidates), noise);
}

ExemplarOutput ExemplarModelImpl::Pairs(const at::Tensor& positives,
                                        const at::Tensor& negatives,
                                        const at::Generator& noise) {
  // The exemplar of every pair is a positive: each is encoded once.
  const auto [mean, log_var] = exemplar_encoder_->forward(positives);
  return Discriminate(
      {at::cat({mean, mean}), at::cat({log_var, log_var})},
      candidate_encoder_->forward(at::cat({positives, negatives})), &noise);
}

ExemplarOutput ExemplarModelImpl::Discriminate(
    const std::pair<at::Tensor, at::Tensor>& exemplars,
    const std::pair<at::Tensor, at::Tensor>& candidates,
    const at::Generator* noise) {
  const auto& [mean1, log_var1] = exemplars;
  const auto& [mean2, log_var2] = candidates;
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
  const at::Tensor labels =
      at::cat({at::ones({b}, positives.options()),
               at::zeros({negatives.size(0)}, positives.options())});
  const ExemplarOutput out = model.Pairs(positives, negatives, noise);
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
