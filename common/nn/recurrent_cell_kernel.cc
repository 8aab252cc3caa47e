#include "common/nn/recurrent_cell_kernel.h"

#include <ATen/ATen.h>
#include <cblas.h>

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "common/nn/float_copy.h"

namespace vantage {
namespace {

float Sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }

// out[rows, n] = in[rows, k] x weight[n, k]^T + bias[n]; rows of `in` are
// `stride` floats apart.
void Project(const float* in, int64_t rows, int64_t k, int64_t stride,
             const std::vector<float>& weight, const std::vector<float>& bias,
             int64_t n, float* out) {
  for (int64_t r = 0; r < rows; ++r) {
    std::copy(bias.begin(), bias.end(), out + r * n);
  }
  // One environment: a matrix-vector product, which BLAS does faster.
  if (rows == 1) {
    cblas_sgemv(CblasRowMajor, CblasNoTrans, static_cast<int>(n),
                static_cast<int>(k), 1.0f, weight.data(), static_cast<int>(k),
                in, 1, 1.0f, out, 1);
    return;
  }
  cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasTrans, static_cast<int>(rows),
              static_cast<int>(n), static_cast<int>(k), 1.0f, in,
              static_cast<int>(stride), weight.data(), static_cast<int>(k),
              1.0f, out, static_cast<int>(n));
}

}  // namespace

absl::StatusOr<RecurrentCellKernel> RecurrentCellKernel::Create(
    Kind kind, const at::Tensor& weight_ih, const at::Tensor& weight_hh,
    const at::Tensor& bias_ih, const at::Tensor& bias_hh) {
  const int64_t gates = kind == Kind::kGru ? 3 : 4;
  if (weight_ih.dim() != 2 || weight_hh.dim() != 2 ||
      weight_hh.size(0) % gates != 0 ||
      weight_hh.size(1) * gates != weight_hh.size(0) ||
      weight_ih.size(0) != weight_hh.size(0) ||
      bias_ih.numel() != weight_hh.size(0) ||
      bias_hh.numel() != weight_hh.size(0)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "a ", kind == Kind::kGru ? "GRU" : "LSTM", " cell needs weight_ih [",
        gates, "H, I], weight_hh [", gates, "H, H] and biases [", gates, "H]"));
  }
  RecurrentCellKernel kernel;
  kernel.kind_ = kind;
  kernel.hidden_ = weight_hh.size(1);
  kernel.inputs_ = weight_ih.size(1);
  kernel.gates_ = weight_hh.size(0);
  kernel.weight_ih_ = FloatVector(weight_ih);
  kernel.weight_hh_ = FloatVector(weight_hh);
  kernel.bias_ih_ = FloatVector(bias_ih);
  kernel.bias_hh_ = FloatVector(bias_hh);
  return kernel;
}

void RecurrentCellKernel::Step(const float* inputs, int64_t rows,
                               float* states) {
  const size_t size = static_cast<size_t>(rows * gates_);
  if (from_input_.size() < size) {
    from_input_.resize(size);
    from_hidden_.resize(size);
  }
  // The two projections stay apart: a GRU's candidate takes r times the
  // hidden one alone.
  const int64_t stride = state_size();
  Project(inputs, rows, inputs_, inputs_, weight_ih_, bias_ih_, gates_,
          from_input_.data());
  Project(states, rows, hidden_, stride, weight_hh_, bias_hh_, gates_,
          from_hidden_.data());
  const int64_t h = hidden_;
  for (int64_t r = 0; r < rows; ++r) {
    const float* x = from_input_.data() + r * gates_;
    const float* s = from_hidden_.data() + r * gates_;
    float* state = states + r * stride;
    if (kind_ == Kind::kGru) {
      for (int64_t j = 0; j < h; ++j) {
        const float reset = Sigmoid(x[j] + s[j]);
        const float update = Sigmoid(x[h + j] + s[h + j]);
        const float candidate = std::tanh(x[2 * h + j] + reset * s[2 * h + j]);
        state[j] = (1.0f - update) * candidate + update * state[j];
      }
    } else {
      float* memory = state + h;
      for (int64_t j = 0; j < h; ++j) {
        const float in = Sigmoid(x[j] + s[j]);
        const float forget = Sigmoid(x[h + j] + s[h + j]);
        const float candidate = std::tanh(x[2 * h + j] + s[2 * h + j]);
        const float out = Sigmoid(x[3 * h + j] + s[3 * h + j]);
        memory[j] = forget * memory[j] + in * candidate;
        state[j] = out * std::tanh(memory[j]);
      }
    }
  }
}

}  // namespace vantage
