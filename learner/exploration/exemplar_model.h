#ifndef VANTAGE_LEARNER_EXPLORATION_EXEMPLAR_MODEL_H_
#define VANTAGE_LEARNER_EXPLORATION_EXEMPLAR_MODEL_H_

// EX2's amortized exemplar model: two encoders map an exemplar and a
// candidate to Gaussian latents (mean and log-variance heads, sampled by
// reparameterisation when training), and a discriminator on the two
// latents side by side says how likely the candidate is the exemplar
// itself. Trained to tell (x, x) from (x, x') with x' from earlier
// batches, D(x, x) is high where x is rare: its odds are the novelty bonus.

#include <ATen/core/Generator.h>
#include <torch/nn/module.h>
#include <torch/nn/modules/container/modulelist.h>

#include <cstdint>
#include <utility>
#include <vector>

#include "learner/exploration/ex2_config.h"

namespace vantage {

// Linear layers of `sizes` (after `inputs`), Glorot-uniform weights and
// zero biases as Lasagne's defaults; tanh after each layer, or after all
// but the last when `linear_output`.
class GlorotMlpImpl : public torch::nn::Module {
 public:
  GlorotMlpImpl(int64_t inputs, const std::vector<int64_t>& sizes,
                bool linear_output);
  at::Tensor forward(const at::Tensor& x);
  const torch::nn::ModuleList& layers() const { return layers_; }
  bool linear_output() const { return linear_output_; }

 private:
  torch::nn::ModuleList layers_;
  bool linear_output_;
};
TORCH_MODULE(GlorotMlp);

// EX2's ConvNet for images [C, H, W] (its Doom and Atari scripts): two
// convolutions of 16 4x4 filters, stride 2, zero-padded by 3 on every
// side (Lasagne's pad='full'), tanh after each, flattened. Glorot-uniform
// weights, zero biases.
class Ex2ConvTrunkImpl : public torch::nn::Module {
 public:
  explicit Ex2ConvTrunkImpl(const std::vector<int64_t>& image_shape);
  // [B, C * H * W] -> [B, features()].
  at::Tensor forward(const at::Tensor& images);
  int64_t features() const { return features_; }

 private:
  std::vector<int64_t> image_shape_;
  torch::nn::ModuleList layers_;
  int64_t features_ = 0;
};
TORCH_MODULE(Ex2ConvTrunk);

// The trunk is a tanh MLP, or with a convolutional model the ConvNet over
// the image (the first image_size inputs), the rest of the inputs (the
// action, if modelled) joined to its features as EX2's SiameseConv does.
class ExemplarEncoderImpl : public torch::nn::Module {
 public:
  ExemplarEncoderImpl(int64_t inputs, const Ex2Config& config,
                      const std::vector<int64_t>& image_shape);
  // The latent's mean and log-variance, [B, feature_dim] each.
  std::pair<at::Tensor, at::Tensor> forward(const at::Tensor& x);
  // Null in a convolutional model.
  const GlorotMlp& trunk() const { return trunk_; }
  const GlorotMlp& mean() const { return mean_; }
  const GlorotMlp& log_variance() const { return log_variance_; }

 private:
  GlorotMlp trunk_{nullptr};
  Ex2ConvTrunk conv_{nullptr};
  int64_t image_size_ = 0;
  GlorotMlp mean_{nullptr};
  GlorotMlp log_variance_{nullptr};
};
TORCH_MODULE(ExemplarEncoder);

struct ExemplarOutput {
  at::Tensor probability;  // [B] D(exemplar, candidate), a sigmoid
  at::Tensor kl;           // [B] KL of both latents to N(0, I), summed
};

class ExemplarModelImpl : public torch::nn::Module {
 public:
  // `image_shape` [C, H, W]: the image at the front of every input row,
  // for config.convolutional(); empty otherwise.
  ExemplarModelImpl(int64_t inputs, const Ex2Config& config,
                    const std::vector<int64_t>& image_shape = {});

  // With `noise`, latents are sampled from it (training); without, they
  // are the means (the bonus).
  ExemplarOutput forward(const at::Tensor& exemplars,
                         const at::Tensor& candidates,
                         const at::Generator* noise);
  // The training pairs: (x, x) for each positive x, then (x, x') for the
  // i-th positive and the i-th negative; latents drawn from `noise` as
  // forward draws them for (cat(x, x), cat(x, x')).
  ExemplarOutput Pairs(const at::Tensor& positives, const at::Tensor& negatives,
                       const at::Generator& noise);

  int64_t inputs() const { return inputs_; }
  bool convolutional() const { return convolutional_; }
  const ExemplarEncoder& exemplar_encoder() const { return exemplar_encoder_; }
  const ExemplarEncoder& candidate_encoder() const {
    return candidate_encoder_;
  }
  const GlorotMlp& discriminator() const { return discriminator_; }

 private:
  // The discriminator on latents drawn from both encoders' (mean,
  // log-variance).
  ExemplarOutput Discriminate(
      const std::pair<at::Tensor, at::Tensor>& exemplars,
      const std::pair<at::Tensor, at::Tensor>& candidates,
      const at::Generator* noise);

  int64_t inputs_;
  bool convolutional_;
  ExemplarEncoder exemplar_encoder_{nullptr};
  ExemplarEncoder candidate_encoder_{nullptr};
  GlorotMlp discriminator_{nullptr};
};
TORCH_MODULE(ExemplarModel);

struct ExemplarLoss {
  at::Tensor loss;  // scalar, to minimise
  double accuracy;  // share of pairs on the right side of 0.5
};

// -mean(log Bernoulli(label | D) - kl_weight * KL) over the pairs
// (x, x) labelled 1 and (x, x') labelled 0, D clipped to [1e-6, 1 - 1e-6]
// as EX2's reference code does.
ExemplarLoss ComputeExemplarLoss(ExemplarModelImpl& model,
                                 const at::Tensor& positives,
                                 const at::Tensor& negatives, double kl_weight,
                                 const at::Generator& noise);

// -log p(x) = log(D / (1 - D)) with D = D(x, x) on the mean latents,
// clipped to [1e-5, 1 - 1e-5]: [B], without gradients.
at::Tensor NoveltyBonus(ExemplarModelImpl& model, const at::Tensor& x);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_EXPLORATION_EXEMPLAR_MODEL_H_
