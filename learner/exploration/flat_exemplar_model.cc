#include "learner/exploration/flat_exemplar_model.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/util/scratch_buffer.h"
#include "learner/exploration/exemplar_model.h"

namespace vantage {

absl::StatusOr<FlatExemplarModel> FlatExemplarModel::Create(
    const ExemplarModelImpl& model, const Ex2Config& config,
    std::vector<at::Tensor> parameters) {
  if (model.convolutional()) {
    return absl::UnimplementedError(
        "the flat fit lays out MLP encoders only; a convolutional model fits "
        "through autograd");
  }
  absl::StatusOr<FlatParameterClaims> claims =
      FlatParameterClaims::Create(std::move(parameters));
  if (!claims.ok()) return claims.status();
  FlatExemplarModel flat;
  flat.size_ = claims->size();
  flat.features_ = config.feature_dim;
  const int64_t width = config.hidden.front();
  absl::Status status;
  const auto lay_out = [&](const GlorotMlp& module, int64_t inputs,
                           int64_t outputs, bool squash_last, FlatMlp& mlp) {
    if (!status.ok()) return;
    absl::StatusOr<FlatMlp> laid = FlatMlp::LayOut(
        module->layers(), inputs, outputs, squash_last, *claims);
    if (laid.ok()) {
      mlp = *std::move(laid);
    } else {
      status = laid.status();
    }
  };
  for (auto [encoder, module] :
       {std::pair{&flat.exemplar_, &model.exemplar_encoder()},
        std::pair{&flat.candidate_, &model.candidate_encoder()}}) {
    lay_out((*module)->trunk(), model.inputs(), width, true, encoder->trunk);
    lay_out((*module)->mean(), width, flat.features_, false, encoder->mean);
    lay_out((*module)->log_variance(), width, flat.features_, false,
            encoder->log_variance);
  }
  lay_out(model.discriminator(), 2 * flat.features_, 1, false,
          flat.discriminator_);
  if (!status.ok()) return status;
  if (!claims->AllClaimed()) {
    return absl::UnimplementedError(
        "a parameter of the exemplar model belongs to none of its layers");
  }
  return flat;
}

void FlatExemplarModel::Encoder::Forward(const float* parameters,
                                         const float* inputs, int64_t rows) {
  trunk.Forward(parameters, inputs, rows);
  mean.Forward(parameters, trunk.output(), rows);
  log_variance.Forward(parameters, trunk.output(), rows);
  // exp(lv / 2) once per row, vectorised: scalar expf at every draw, in
  // the sampling and again in the gradients, took half of a step.
  const int64_t n = rows * mean.outputs();
  const float* lv = log_variance.output();
  float* s = GrowScratch(std_dev, n);
  for (int64_t i = 0; i < n; ++i) s[i] = 0.5f * lv[i];
  at::from_blob(s, {n}).exp_();
}

void FlatExemplarModel::Encoder::Backward(const float* parameters,
                                          float* gradients, const float* inputs,
                                          int64_t rows) {
  const float* h = trunk.output();
  const int64_t n = rows * trunk.outputs();
  float* d_h = GrowScratch(d_trunk, n);
  float* d_other = GrowScratch(d_trunk_other, n);
  mean.Backward(parameters, gradients, h, rows, d_mean, d_h);
  log_variance.Backward(parameters, gradients, h, rows, d_log_variance,
                        d_other);
  // Both heads read the trunk's last tanh.
  for (int64_t i = 0; i < n; ++i) {
    d_h[i] = (d_h[i] + d_other[i]) * (1.0f - h[i] * h[i]);
  }
  trunk.Backward(parameters, gradients, inputs, rows, d_trunk);
}

void FlatExemplarModel::LatentGradients(Encoder& encoder,
                                        const float* d_latents, int64_t stride,
                                        int64_t column, const float* epsilon,
                                        int64_t draws, int64_t rows,
                                        float kl_scale) {
  const int64_t f = features_;
  const float* mean = encoder.mean.output();
  const float* std_dev = encoder.std_dev.data();
  float* d_mean = GrowScratch(encoder.d_mean, rows * f);
  float* d_log_variance = GrowScratch(encoder.d_log_variance, rows * f);
  std::fill_n(d_mean, rows * f, 0.0f);
  std::fill_n(d_log_variance, rows * f, 0.0f);
  for (int64_t i = 0; i < draws; ++i) {
    const int64_t r = i % rows;
    for (int64_t j = 0; j < f; ++j) {
      const int64_t k = r * f + j;
      const float dz = d_latents[i * stride + column + j];
      const float s = std_dev[k];
      // z = mean + exp(lv / 2) * epsilon, and each draw's KL term
      // -1/2 (1 + lv - mean^2 - exp(lv)).
      d_mean[k] += dz + kl_scale * mean[k];
      d_log_variance[k] +=
          dz * epsilon[i * f + j] * 0.5f * s + kl_scale * 0.5f * (s * s - 1.0f);
    }
  }
}

double FlatExemplarModel::SampleLatents(Encoder& encoder, const float* epsilon,
                                        int64_t draws, int64_t rows,
                                        int64_t column) {
  const int64_t f = features_;
  const float* mean = encoder.mean.output();
  const float* log_variance = encoder.log_variance.output();
  const float* std_dev = encoder.std_dev.data();
  float* latents = GrowScratch(latents_, draws * 2 * f);
  double kl = 0.0;
  for (int64_t i = 0; i < draws; ++i) {
    const int64_t r = i % rows;
    for (int64_t j = 0; j < f; ++j) {
      const int64_t k = r * f + j;
      latents[i * 2 * f + column + j] =
          mean[k] + std_dev[k] * epsilon[i * f + j];
      const double m = mean[k], s = std_dev[k];
      kl -= 0.5 * (1.0 + log_variance[k] - m * m - s * s);
    }
  }
  return kl;
}

double FlatExemplarModel::Discriminate(int64_t positives, int64_t rows,
                                       int64_t& right) {
  float* probability = discriminator_.output();
  at::from_blob(probability, {rows}).sigmoid_();
  constexpr float kLow = 1e-6f, kHigh = 1.0f - 1e-6f;
  float* d_logits = GrowScratch(d_logits_, rows);
  const float inverse_rows = 1.0f / static_cast<float>(rows);
  double log_likelihood = 0.0;
  right = 0;
  for (int64_t i = 0; i < rows; ++i) {
    const float p = probability[i];
    const bool positive = i < positives;
    const float d = std::clamp(p, kLow, kHigh);
    log_likelihood += positive ? std::log(d) : std::log(1.0f - d);
    right += (p > 0.5f) == positive;
    // d(-log likelihood)/d logit through the sigmoid, zero where clipped.
    const bool inside = p >= kLow && p <= kHigh;
    d_logits[i] = inside ? (p - (positive ? 1.0f : 0.0f)) * inverse_rows : 0.0f;
  }
  return log_likelihood;
}

FlatExemplarLoss FlatExemplarModel::LossAndGradient(const float* parameters,
                                                    const at::Tensor& positives,
                                                    const at::Tensor& negatives,
                                                    double kl_weight,
                                                    at::Generator& noise,
                                                    float* gradients) {
  const int64_t b = positives.size(0);
  TORCH_CHECK(negatives.size(0) == b,
              "the exemplar model pairs each positive with one negative");
  const int64_t rows = 2 * b;
  const int64_t f = features_;
  const at::Tensor exemplars = positives.to(at::kFloat).contiguous();
  const at::Tensor candidates =
      at::cat({exemplars, negatives.to(at::kFloat)}).contiguous();
  exemplar_.Forward(parameters, exemplars.data_ptr<float>(), b);
  candidate_.Forward(parameters, candidates.data_ptr<float>(), rows);
  // The draws in ComputeExemplarLoss's order: the exemplars' (one per pair,
  // of their 2B rows), then the candidates'.
  const at::TensorOptions options(at::kFloat);
  const at::Tensor epsilon1 = at::randn({rows, f}, noise, options);
  const at::Tensor epsilon2 = at::randn({rows, f}, noise, options);
  const float* e1 = epsilon1.data_ptr<float>();
  const float* e2 = epsilon2.data_ptr<float>();
  const double kl = SampleLatents(exemplar_, e1, rows, b, 0) +
                    SampleLatents(candidate_, e2, rows, rows, f);

  discriminator_.Forward(parameters, latents_.data(), rows);
  int64_t right = 0;
  const double log_likelihood = Discriminate(b, rows, right);
  float* d_latents = GrowScratch(d_latents_, rows * 2 * f);
  discriminator_.Backward(parameters, gradients, latents_.data(), rows,
                          d_logits_, d_latents);

  const float kl_scale =
      static_cast<float>(kl_weight) / static_cast<float>(rows);
  LatentGradients(exemplar_, d_latents, 2 * f, 0, e1, rows, b, kl_scale);
  exemplar_.Backward(parameters, gradients, exemplars.data_ptr<float>(), b);
  LatentGradients(candidate_, d_latents, 2 * f, f, e2, rows, rows, kl_scale);
  candidate_.Backward(parameters, gradients, candidates.data_ptr<float>(),
                      rows);

  FlatExemplarLoss result;
  result.loss = (-log_likelihood + kl_weight * kl) / static_cast<double>(rows);
  result.accuracy = static_cast<double>(right) / static_cast<double>(rows);
  return result;
}

}  // namespace vantage
