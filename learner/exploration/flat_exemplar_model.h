#ifndef VANTAGE_LEARNER_EXPLORATION_FLAT_EXEMPLAR_MODEL_H_
#define VANTAGE_LEARNER_EXPLORATION_FLAT_EXEMPLAR_MODEL_H_

// EX2's exemplar model trained without autograd: the loss of
// ComputeExemplarLoss and its gradient written out by hand over FlatMlp's
// layers, in one flat array laid out as the model's parameters(). The
// model is a few dozen layers 16-32 wide, so LibTorch's per-operator and
// autograd costs are most of an autograd step; here a step is the BLAS
// calls and a few loops. The exemplar encoder reads each positive once
// (autograd's pairs (x, x) read it twice, for two noise draws).
// tests/learner/exploration/flat_exemplar_model_test.cc checks the loss
// and every gradient against autograd.

#include <ATen/core/Generator.h>
#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "learner/algorithms/flat_mlp.h"
#include "learner/exploration/ex2_config.h"

namespace vantage {

class ExemplarModelImpl;

struct FlatExemplarLoss {
  double loss = 0.0;      // ComputeExemplarLoss's
  double accuracy = 0.0;  // share of pairs on the right side of 0.5
};

class FlatExemplarModel {
 public:
  // `model` built with `config`; `parameters` its parameters(), the flat
  // array's layout.
  static absl::StatusOr<FlatExemplarModel> Create(
      const ExemplarModelImpl& model, const Ex2Config& config,
      std::vector<at::Tensor> parameters);

  int64_t size() const { return size_; }

  // ComputeExemplarLoss's loss on `positives` and `negatives` (the same
  // number of rows, float [B, inputs]) with the model's parameters read
  // from `parameters`, drawing the latents' noise from `noise` as it does
  // (so the same generator state gives the same draws), and its gradient
  // written into `gradients` [size()].
  FlatExemplarLoss LossAndGradient(const float* parameters,
                                   const at::Tensor& positives,
                                   const at::Tensor& negatives,
                                   double kl_weight, at::Generator& noise,
                                   float* gradients);

 private:
  // An encoder: a trunk (tanh after every layer) under mean and
  // log-variance heads (linear outputs).
  struct Encoder {
    FlatMlp trunk, mean, log_variance;
    std::vector<float> std_dev;  // exp(log_variance / 2) of the last Forward
    std::vector<float> d_mean, d_log_variance, d_trunk, d_trunk_other;
    void Forward(const float* parameters, const float* inputs, int64_t rows);
    // From d_mean and d_log_variance [rows, features] (used as scratch).
    void Backward(const float* parameters, float* gradients,
                  const float* inputs, int64_t rows);
  };
  FlatExemplarModel() = default;
  // The latents `encoder` draws (its last Forward's `rows` rows, draw i
  // from row i % rows, with the noise `epsilon` [draws, f]) into column
  // `column` of latents_ [draws, 2f]; returns their KL terms' sum.
  double SampleLatents(Encoder& encoder, const float* epsilon, int64_t draws,
                       int64_t rows, int64_t column);
  // D of the discriminator's last Forward (the first `positives` of `rows`
  // pairs labelled 1): their log-likelihood (D clipped to [1e-6, 1 -
  // 1e-6]), the pairs on the right side of 0.5 in `right`, and d loss / d
  // logits into d_logits_.
  double Discriminate(int64_t positives, int64_t rows, int64_t& right);
  // d loss / d the latent means and log-variances of `encoder`'s `rows`
  // rows, given d loss / d the latents it sampled (`d_latents`, column
  // `column` of rows of `stride`) and the noise `epsilon` [draws, f]:
  // draw i sampled from the encoder's row i % rows.
  void LatentGradients(Encoder& encoder, const float* d_latents, int64_t stride,
                       int64_t column, const float* epsilon, int64_t draws,
                       int64_t rows, float kl_scale);

  int64_t size_ = 0;
  int64_t features_ = 0;
  Encoder exemplar_, candidate_;
  FlatMlp discriminator_;
  std::vector<float> latents_, d_logits_, d_latents_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_EXPLORATION_FLAT_EXEMPLAR_MODEL_H_
