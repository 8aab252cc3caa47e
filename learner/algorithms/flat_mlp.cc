#include "learner/algorithms/flat_mlp.h"

#include <ATen/ATen.h>
#include <cblas.h>
#include <torch/nn/modules/container/modulelist.h>
#include <torch/nn/modules/linear.h>

#include <algorithm>
#include <cstring>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/util/scratch_buffer.h"

namespace vantage {

absl::StatusOr<FlatParameterClaims> FlatParameterClaims::Create(
    std::vector<at::Tensor> tensors) {
  FlatParameterClaims claims;
  for (const at::Tensor& p : tensors) {
    if (p.scalar_type() != at::kFloat || !p.is_contiguous() || !p.is_cpu()) {
      return absl::UnimplementedError(
          "a parameter is not a contiguous float tensor on the CPU");
    }
    claims.offsets_.push_back(claims.size_);
    claims.size_ += p.numel();
  }
  claims.claimed_.assign(tensors.size(), false);
  claims.tensors_ = std::move(tensors);
  return claims;
}

int64_t FlatParameterClaims::Claim(const at::Tensor& tensor) {
  for (size_t i = 0; i < tensors_.size(); ++i) {
    if (tensors_[i].unsafeGetTensorImpl() == tensor.unsafeGetTensorImpl() &&
        !claimed_[i]) {
      claimed_[i] = true;
      return offsets_[i];
    }
  }
  return -1;
}

bool FlatParameterClaims::AllClaimed() const {
  return std::find(claimed_.begin(), claimed_.end(), false) == claimed_.end();
}

absl::StatusOr<FlatMlp> FlatMlp::LayOut(const torch::nn::ModuleList& layers,
                                        int64_t inputs, int64_t outputs,
                                        bool squash_last,
                                        FlatParameterClaims& claims) {
  FlatMlp mlp;
  mlp.squash_last_ = squash_last;
  int64_t width = inputs;
  for (size_t i = 0; i < layers->size(); ++i) {
    const auto* linear = layers->ptr(i)->as<torch::nn::LinearImpl>();
    if (linear == nullptr) {
      return absl::UnimplementedError(
          absl::StrCat("layer ", i, " is not a Linear layer"));
    }
    Layer layer;
    layer.outputs = linear->weight.size(0);
    layer.inputs = linear->weight.size(1);
    layer.weight = claims.Claim(linear->weight);
    layer.bias = linear->bias.defined() ? claims.Claim(linear->bias) : -1;
    if (layer.inputs != width || layer.weight < 0 || layer.bias < 0) {
      return absl::UnimplementedError(
          absl::StrCat("layer ", i, " is not a biased Linear layer on ", width,
                       " inputs whose parameters are the given ones"));
    }
    width = layer.outputs;
    mlp.layers_.push_back(layer);
  }
  if (mlp.layers_.empty() || width != outputs) {
    return absl::UnimplementedError(
        absl::StrCat("an MLP ends in ", width, " outputs, not ", outputs));
  }
  mlp.outputs_.resize(mlp.layers_.size());
  return mlp;
}

void FlatMlp::Forward(const float* parameters, const float* inputs,
                      int64_t rows) {
  const float* x = inputs;
  for (size_t l = 0; l < layers_.size(); ++l) {
    const Layer& layer = layers_[l];
    float* y = GrowScratch(outputs_[l], rows * layer.outputs);
    const float* bias = parameters + layer.bias;
    // As addmm: the bias, then the product added onto it.
    for (int64_t r = 0; r < rows; ++r) {
      std::memcpy(y + r * layer.outputs, bias, sizeof(float) * layer.outputs);
    }
    cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasTrans, rows, layer.outputs,
                layer.inputs, 1.0f, x, layer.inputs, parameters + layer.weight,
                layer.inputs, 1.0f, y, layer.outputs);
    if (l + 1 < layers_.size() || squash_last_) {
      // LibTorch's vectorised tanh, the one the modules use: libm's scalar
      // tanhf would take most of the step.
      at::from_blob(y, {rows * layer.outputs}).tanh_();
    }
    x = y;
  }
}

void FlatMlp::Backward(const float* parameters, float* gradients,
                       const float* inputs, int64_t rows,
                       std::vector<float>& gradient, float* d_inputs) {
  for (size_t l = layers_.size(); l-- > 0;) {
    const Layer& layer = layers_[l];
    const float* x = l == 0 ? inputs : outputs_[l - 1].data();
    const float* dy = gradient.data();
    cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, layer.outputs,
                layer.inputs, rows, 1.0f, dy, layer.outputs, x, layer.inputs,
                0.0f, gradients + layer.weight, layer.inputs);
    float* db = gradients + layer.bias;
    std::fill(db, db + layer.outputs, 0.0f);
    for (int64_t r = 0; r < rows; ++r) {
      for (int64_t j = 0; j < layer.outputs; ++j) {
        db[j] += dy[r * layer.outputs + j];
      }
    }
    if (l == 0 && d_inputs == nullptr) break;
    float* dx = l == 0 ? d_inputs : GrowScratch(scratch_, rows * layer.inputs);
    cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, rows, layer.inputs,
                layer.outputs, 1.0f, dy, layer.outputs,
                parameters + layer.weight, layer.inputs, 0.0f, dx,
                layer.inputs);
    if (l == 0) break;
    // Through the tanh whose outputs x are.
    for (int64_t i = 0; i < rows * layer.inputs; ++i) {
      dx[i] *= 1.0f - x[i] * x[i];
    }
    std::swap(gradient, scratch_);
  }
}

}  // namespace vantage
