#include "common/nn/mlp_policy_kernel.h"

#include <ATen/ATen.h>
#include <cblas.h>
#include <torch/nn/modules/linear.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"
#include "common/nn/cpu_sampling.h"
#include "common/nn/distributions.h"
#include "common/nn/float_copy.h"
#include "common/nn/networks.h"
#include "common/nn/recurrent_trunk.h"
#include "common/nn/running_mean_std.h"
#include "common/util/scratch_buffer.h"

namespace vantage {
namespace {

std::vector<double> DoubleVector(const at::Tensor& tensor) {
  const at::Tensor flat = tensor.detach().to(at::kDouble).contiguous();
  return std::vector<double>(flat.data_ptr<double>(),
                             flat.data_ptr<double>() + flat.numel());
}

}  // namespace

absl::StatusOr<MlpPolicyKernel> MlpPolicyKernel::Create(
    const EnvSpec& spec, PolicyNetworkImpl& policy,
    const RunningMeanStd& normalizer, double observation_clip) {
  if (!policy.conv_torso().is_empty() || !policy.dict_torso().is_empty()) {
    return absl::UnimplementedError(
        "the policy has a convolutional or Dict torso, which only LibTorch "
        "runs");
  }
  if (normalizer.size() != spec.observation_size) {
    return absl::InvalidArgumentError(
        absl::StrCat("the normaliser is of size ", normalizer.size(),
                     ", the observations of size ", spec.observation_size));
  }
  MlpPolicyKernel kernel;
  kernel.spec_ = spec;
  kernel.widest_ = spec.observation_size;
  kernel.discrete_ = policy.discrete();
  kernel.heads_ = spec.action_heads();
  kernel.clip_ = observation_clip;
  kernel.mean_ = DoubleVector(normalizer.mean());
  kernel.scale_ = DoubleVector(at::sqrt(normalizer.var() + 1e-8));
  int64_t width = spec.observation_size;
  if (policy.recurrent()) {
    if (absl::Status status = kernel.AddCore(policy, width); !status.ok()) {
      return status;
    }
  }
  if (absl::Status status =
          kernel.AddLayers(policy.body()->layers(), "policy", width);
      !status.ok()) {
    return status;
  }
  if (kernel.layers_.size() == kernel.encoder_layers_ ||
      width != spec.action_size) {
    return absl::UnimplementedError(absl::StrCat("the policy's MLP ends in ",
                                                 width, " outputs, not ",
                                                 spec.action_size));
  }
  kernel.output_size_ = width;
  if (!kernel.discrete_) {
    kernel.log_std_ = FloatVector(policy.log_std());
    for (float log_std : kernel.log_std_) {
      kernel.std_.push_back(std::exp(log_std));
      kernel.inv_std_.push_back(std::exp(-log_std));
    }
  }
  return kernel;
}

absl::Status MlpPolicyKernel::AddLayers(const torch::nn::ModuleList& mlp,
                                        const char* name, int64_t& width) {
  for (size_t i = 0; i < mlp->size(); ++i) {
    const auto& linear = mlp->at<torch::nn::LinearImpl>(i);
    Layer layer;
    layer.outputs = linear.weight.size(0);
    layer.inputs = linear.weight.size(1);
    if (layer.inputs != width || !linear.bias.defined()) {
      return absl::UnimplementedError(
          absl::StrCat("layer ", i, " of the ", name,
                       " is not a biased Linear layer on ", width, " inputs"));
    }
    layer.weight = FloatVector(linear.weight);
    layer.bias = FloatVector(linear.bias);
    width = layer.outputs;
    widest_ = std::max(widest_, width);
    layers_.push_back(std::move(layer));
  }
  return absl::OkStatus();
}

absl::Status MlpPolicyKernel::AddCore(PolicyNetworkImpl& policy,
                                      int64_t& width) {
  const RecurrentTrunk& trunk = policy.trunk();
  if (!trunk->conv_torso().is_empty()) {
    return absl::UnimplementedError(
        "the policy's core follows a convolutional torso, which only "
        "LibTorch runs");
  }
  if (!trunk->encoder().is_empty()) {
    if (absl::Status status =
            AddLayers(trunk->encoder()->layers(), "policy's encoder", width);
        !status.ok()) {
      return status;
    }
  }
  encoder_layers_ = layers_.size();
  absl::StatusOr<RecurrentCellKernel> cell =
      trunk->core() == Core::kLstm
          ? RecurrentCellKernel::Create(
                RecurrentCellKernel::Kind::kLstm, trunk->lstm()->weight_ih,
                trunk->lstm()->weight_hh, trunk->lstm()->bias_ih,
                trunk->lstm()->bias_hh)
          : RecurrentCellKernel::Create(
                RecurrentCellKernel::Kind::kGru, trunk->gru()->weight_ih,
                trunk->gru()->weight_hh, trunk->gru()->bias_ih,
                trunk->gru()->bias_hh);
  if (!cell.ok()) return cell.status();
  if (cell->input_size() != width) {
    return absl::UnimplementedError(absl::StrCat(
        "the core takes ", cell->input_size(), " inputs, not ", width));
  }
  width = cell->hidden_size();
  widest_ = std::max(widest_, cell->state_size());
  cell_ = std::move(*cell);
  return absl::OkStatus();
}

void MlpPolicyKernel::Inputs(const double* observations, int64_t rows,
                             float* inputs) const {
  const int64_t size = spec_.observation_size;
  if (spec_.byte_observations()) {
    // As NetworkInputs: the bytes as floats times 1 / observation_high.
    const float scale =
        static_cast<float>(1.0 / static_cast<double>(std::max<int64_t>(
                                     spec_.observation_high, 1)));
    for (int64_t i = 0; i < rows * size; ++i) {
      inputs[i] =
          static_cast<float>(static_cast<uint8_t>(observations[i])) * scale;
    }
    return;
  }
  // As RunningMeanStd::Normalize on the float32 copy segments keep: in
  // double, clipped, then back to float.
  for (int64_t r = 0; r < rows; ++r) {
    const double* x = observations + r * size;
    float* out = inputs + r * size;
    for (int64_t j = 0; j < size; ++j) {
      const double stored = static_cast<float>(x[j]);
      const double normalized = (stored - mean_[j]) / scale_[j];
      out[j] =
          static_cast<float>(std::min(std::max(normalized, -clip_), clip_));
    }
  }
}

void MlpPolicyKernel::Apply(const Layer& layer, const float* x, int64_t rows,
                            bool squash, float* y) {
  for (int64_t r = 0; r < rows; ++r) {
    std::copy(layer.bias.begin(), layer.bias.end(), y + r * layer.outputs);
  }
  // y = x W^T + b: a matrix-vector product for one row.
  if (rows == 1) {
    cblas_sgemv(CblasRowMajor, CblasNoTrans, layer.outputs, layer.inputs, 1.0f,
                layer.weight.data(), layer.inputs, x, 1, 1.0f, y, 1);
  } else {
    cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasTrans, rows, layer.outputs,
                layer.inputs, 1.0f, x, layer.inputs, layer.weight.data(),
                layer.inputs, 1.0f, y, layer.outputs);
  }
  if (squash) {
    for (int64_t i = 0; i < rows * layer.outputs; ++i) y[i] = std::tanh(y[i]);
  }
}

void MlpPolicyKernel::Forward(const double* observations, int64_t rows,
                              float* outputs, float* states) {
  float* in = GrowScratch(buffer_a_, rows * widest_);
  float* out = GrowScratch(buffer_b_, rows * widest_);
  Inputs(observations, rows, in);
  for (size_t l = 0; l < layers_.size(); ++l) {
    if (cell_.has_value() && l == encoder_layers_) {
      // The cell's next states, whose hidden parts feed the next layer.
      cell_->Step(in, rows, states);
      const int64_t stride = cell_->state_size();
      const int64_t hidden = cell_->hidden_size();
      for (int64_t r = 0; r < rows; ++r) {
        std::copy(states + r * stride, states + r * stride + hidden,
                  in + r * hidden);
      }
    }
    const bool last = l + 1 == layers_.size();
    Apply(layers_[l], in, rows, !last, last ? outputs : out);
    if (!last) std::swap(in, out);
  }
}

void MlpPolicyKernel::Act(const float* outputs, int64_t rows,
                          at::Generator& generator, float* actions,
                          float* log_probs) {
  const int64_t n = output_size_;
  if (!discrete_) {
    // mean + exp(log_std) * N(0, 1), and its Gaussian log-density.
    // In float, as LibTorch subtracts the constant from a float tensor.
    const float log_sqrt_two_pi = static_cast<float>(kLogSqrtTwoPi);
    float* noise = GrowScratch(noise_, rows * n);
    FillStandardNormal(generator, noise, rows * n);
    for (int64_t r = 0; r < rows; ++r) {
      float log_prob = 0.0f;
      for (int64_t j = 0; j < n; ++j) {
        const int64_t i = r * n + j;
        const float spread = std_[j] * noise[i];
        const float action = outputs[i] + spread;
        actions[i] = action;
        const float z = (action - outputs[i]) * inv_std_[j];
        const float half_square = -0.5f * z * z;
        log_prob += half_square - log_std_[j] - log_sqrt_two_pi;
      }
      log_probs[r] = log_prob;
    }
    return;
  }
  // Head by head (one for Discrete), as PolicyNetworkImpl::Act draws:
  // softmax per row, a categorical draw, and the log-softmax at it, the
  // heads' log-probabilities summed.
  const int64_t width = action_width();
  std::fill(log_probs, log_probs + rows, 0.0f);
  int64_t offset = 0;
  for (int64_t h = 0; h < width; offset += heads_[h], ++h) {
    const int64_t choices = heads_[h];
    float* probabilities = GrowScratch(probabilities_, rows * choices);
    float* maxima = GrowScratch(row_max_, rows);
    float* log_sums = GrowScratch(row_log_sum_, rows);
    for (int64_t r = 0; r < rows; ++r) {
      const float* logits = outputs + r * n + offset;
      float* p = probabilities + r * choices;
      const float top = *std::max_element(logits, logits + choices);
      float sum = 0.0f;
      for (int64_t i = 0; i < choices; ++i) {
        p[i] = std::exp(logits[i] - top);
        sum += p[i];
      }
      for (int64_t i = 0; i < choices; ++i) p[i] /= sum;
      maxima[r] = top;
      log_sums[r] = std::log(sum);
    }
    int64_t* indices = GrowScratch(indices_, rows);
    SampleCategorical(generator, probabilities, rows, choices, indices);
    for (int64_t r = 0; r < rows; ++r) {
      actions[r * width + h] = static_cast<float>(indices[r]);
      log_probs[r] +=
          outputs[r * n + offset + indices[r]] - maxima[r] - log_sums[r];
    }
  }
}

}  // namespace vantage
