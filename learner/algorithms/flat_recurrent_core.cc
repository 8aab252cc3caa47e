#include "learner/algorithms/flat_recurrent_core.h"

#include <cblas.h>

#include <algorithm>
#include <cmath>

#include "common/util/scratch_buffer.h"

namespace vantage {
namespace {

float Sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }

// c[m, n] (+)= a[m, k] b[n, k]^T, row-major with leading dimensions.
void MultiplyByTransposed(int64_t m, int64_t n, int64_t k, const float* a,
                          int64_t lda, const float* b, int64_t ldb, float beta,
                          float* c, int64_t ldc) {
  cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasTrans, static_cast<int>(m),
              static_cast<int>(n), static_cast<int>(k), 1.0f, a,
              static_cast<int>(lda), b, static_cast<int>(ldb), beta, c,
              static_cast<int>(ldc));
}

// Column sums of `rows` rows of `width` added to `out`.
void AddColumnSums(const float* values, int64_t rows, int64_t width,
                   float* out) {
  for (int64_t r = 0; r < rows; ++r) {
    for (int64_t j = 0; j < width; ++j) out[j] += values[r * width + j];
  }
}

}  // namespace

FlatRecurrentCore::FlatRecurrentCore(Core core, int64_t inputs, int64_t hidden,
                                     Offsets offsets)
    : lstm_(core == Core::kLstm),
      inputs_(inputs),
      hidden_(hidden),
      offsets_(offsets) {}

void FlatRecurrentCore::Forward(const float* parameters, const float* encoded,
                                const uint8_t* starts, const float* states,
                                int64_t steps, int64_t chunks) {
  steps_ = steps;
  chunks_ = chunks;
  encoded_ = encoded;
  starts_ = starts;
  const int64_t rows = steps * chunks;
  const int64_t g = gates();
  const int64_t h = hidden_;
  float* projected = GrowScratch(projected_, rows * g);
  GrowScratch(read_, rows * state_size());
  GrowScratch(activations_, rows * g);
  GrowScratch(extra_, rows * h);
  GrowScratch(features_, rows * h);
  float* step = GrowScratch(step_, chunks * g);
  if (lstm_) GrowScratch(cells_, rows * h);
  const float* bias_ih = parameters + offsets_.bias_ih;
  for (int64_t r = 0; r < rows; ++r) {
    std::copy(bias_ih, bias_ih + g, projected + r * g);
  }
  MultiplyByTransposed(rows, g, inputs_, encoded, inputs_,
                       parameters + offsets_.weight_ih, inputs_, 1.0f,
                       projected, g);
  for (int64_t t = 0; t < steps; ++t) {
    ReadStates(t, states, parameters + offsets_.bias_hh);
    MultiplyByTransposed(chunks, g, h, read_.data() + t * chunks * state_size(),
                         state_size(), parameters + offsets_.weight_hh, h, 1.0f,
                         step, g);
    for (int64_t j = 0; j < chunks; ++j) Activate(t * chunks + j, step + j * g);
  }
}

void FlatRecurrentCore::ReadStates(int64_t t, const float* states,
                                   const float* bias_hh) {
  const int64_t h = hidden_;
  const int64_t s = state_size();
  for (int64_t j = 0; j < chunks_; ++j) {
    const int64_t row = t * chunks_ + j;
    float* into = read_.data() + row * s;
    if (starts_[row] != 0) {
      std::fill(into, into + s, 0.0f);
    } else if (t == 0) {
      std::copy(states + j * s, states + (j + 1) * s, into);
    } else {
      const int64_t before = (row - chunks_) * h;
      std::copy(features_.data() + before, features_.data() + before + h, into);
      if (lstm_) {
        std::copy(cells_.data() + before, cells_.data() + before + h, into + h);
      }
    }
    std::copy(bias_hh, bias_hh + gates(), step_.data() + j * gates());
  }
}

void FlatRecurrentCore::Activate(int64_t row, const float* p) {
  const int64_t h = hidden_;
  const float* x = projected_.data() + row * gates();
  const float* state = read_.data() + row * state_size();
  float* a = activations_.data() + row * gates();
  float* e = extra_.data() + row * h;
  float* out = features_.data() + row * h;
  if (!lstm_) {
    for (int64_t k = 0; k < h; ++k) {
      a[k] = Sigmoid(x[k] + p[k]);
      a[h + k] = Sigmoid(x[h + k] + p[h + k]);
      e[k] = p[2 * h + k];
      a[2 * h + k] = std::tanh(x[2 * h + k] + a[k] * e[k]);
      out[k] = (1.0f - a[h + k]) * a[2 * h + k] + a[h + k] * state[k];
    }
    return;
  }
  float* cell = cells_.data() + row * h;
  for (int64_t k = 0; k < h; ++k) {
    a[k] = Sigmoid(x[k] + p[k]);
    a[h + k] = Sigmoid(x[h + k] + p[h + k]);
    a[2 * h + k] = std::tanh(x[2 * h + k] + p[2 * h + k]);
    a[3 * h + k] = Sigmoid(x[3 * h + k] + p[3 * h + k]);
    cell[k] = a[h + k] * state[h + k] + a[k] * a[2 * h + k];
    e[k] = std::tanh(cell[k]);
    out[k] = a[3 * h + k] * e[k];
  }
}

void FlatRecurrentCore::Backward(const float* parameters,
                                 const float* d_features, float* gradients,
                                 float* d_encoded) {
  const int64_t rows = steps_ * chunks_;
  const int64_t g = gates();
  float* d_bias_ih = gradients + offsets_.bias_ih;
  std::fill(gradients + offsets_.weight_hh,
            gradients + offsets_.weight_hh + g * hidden_, 0.0f);
  std::fill(gradients + offsets_.bias_hh, gradients + offsets_.bias_hh + g,
            0.0f);
  std::fill(d_bias_ih, d_bias_ih + g, 0.0f);
  GrowScratch(gate_gradients_, rows * g);
  GrowScratch(step_, chunks_ * g);
  GrowScratch(next_carry_, chunks_ * state_size());
  float* carry = GrowScratch(carry_, chunks_ * state_size());
  std::fill(carry, carry + chunks_ * state_size(), 0.0f);
  for (int64_t t = steps_; t-- > 0;) {
    for (int64_t j = 0; j < chunks_; ++j) {
      RowGradients(t * chunks_ + j, j, d_features);
    }
    StepBackward(t, parameters, gradients);
  }
  // The input projections of every step at once.
  const float* from_input = gate_gradients_.data();
  cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, static_cast<int>(g),
              static_cast<int>(inputs_), static_cast<int>(rows), 1.0f,
              from_input, static_cast<int>(g), encoded_,
              static_cast<int>(inputs_), 0.0f, gradients + offsets_.weight_ih,
              static_cast<int>(inputs_));
  AddColumnSums(from_input, rows, g, d_bias_ih);
  cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans, static_cast<int>(rows),
              static_cast<int>(inputs_), static_cast<int>(g), 1.0f, from_input,
              static_cast<int>(g), parameters + offsets_.weight_ih,
              static_cast<int>(inputs_), 0.0f, d_encoded,
              static_cast<int>(inputs_));
}

// Per row, the gradient of the gates' pre-activations through the input
// projection; per chunk, through the hidden one (the GRU's candidate takes
// r times its hidden term); and what passes straight to the state read.
void FlatRecurrentCore::RowGradients(int64_t row, int64_t j,
                                     const float* d_features) {
  const int64_t h = hidden_;
  const int64_t s = state_size();
  const float* a = activations_.data() + row * gates();
  const float* e = extra_.data() + row * h;
  const float* state = read_.data() + row * s;
  const float* carry = carry_.data() + j * s;
  float* gx = gate_gradients_.data() + row * gates();
  float* gh = step_.data() + j * gates();
  float* into = next_carry_.data() + j * s;
  for (int64_t k = 0; k < h; ++k) {
    const float dh = d_features[row * h + k] + carry[k];
    if (!lstm_) {
      const float r = a[k], z = a[h + k], n = a[2 * h + k];
      const float dn = dh * (1.0f - z) * (1.0f - n * n);
      const float dr = dn * e[k] * r * (1.0f - r);
      const float dz = dh * (state[k] - n) * z * (1.0f - z);
      gx[k] = gh[k] = dr;
      gx[h + k] = gh[h + k] = dz;
      gx[2 * h + k] = dn;
      gh[2 * h + k] = dn * r;
      into[k] = dh * z;
    } else {
      const float i = a[k], f = a[h + k], c = a[2 * h + k], o = a[3 * h + k];
      const float dc = carry[h + k] + dh * o * (1.0f - e[k] * e[k]);
      gx[k] = gh[k] = dc * c * i * (1.0f - i);
      gx[h + k] = gh[h + k] = dc * state[h + k] * f * (1.0f - f);
      gx[2 * h + k] = gh[2 * h + k] = dc * i * (1.0f - c * c);
      gx[3 * h + k] = gh[3 * h + k] = dh * e[k] * o * (1.0f - o);
      into[k] = 0.0f;
      into[h + k] = dc * f;
    }
  }
}

// dW_hh += G_h^T h_read and the read states' gradient G_h W_hh, carried to
// the step before unless the state was zeroed at an episode start.
void FlatRecurrentCore::StepBackward(int64_t t, const float* parameters,
                                     float* gradients) {
  const int64_t g = gates();
  const int64_t h = hidden_;
  const int64_t s = state_size();
  const float* from_hidden = step_.data();
  float* next = next_carry_.data();
  cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, static_cast<int>(g),
              static_cast<int>(h), static_cast<int>(chunks_), 1.0f, from_hidden,
              static_cast<int>(g), read_.data() + t * chunks_ * s,
              static_cast<int>(s), 1.0f, gradients + offsets_.weight_hh,
              static_cast<int>(h));
  AddColumnSums(from_hidden, chunks_, g, gradients + offsets_.bias_hh);
  cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans,
              static_cast<int>(chunks_), static_cast<int>(h),
              static_cast<int>(g), 1.0f, from_hidden, static_cast<int>(g),
              parameters + offsets_.weight_hh, static_cast<int>(h), 1.0f, next,
              static_cast<int>(s));
  for (int64_t j = 0; j < chunks_; ++j) {
    const bool start = starts_[t * chunks_ + j] != 0;
    for (int64_t k = 0; k < s; ++k) {
      carry_[j * s + k] = start ? 0.0f : next[j * s + k];
    }
  }
}

}  // namespace vantage
