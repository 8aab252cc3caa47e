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
  const int64_t s = state_size();
  float* projected = GrowScratch(projected_, rows * g);
  float* read = GrowScratch(read_, rows * s);
  float* activations = GrowScratch(activations_, rows * g);
  float* extra = GrowScratch(extra_, rows * h);
  float* features = GrowScratch(features_, rows * h);
  float* step = GrowScratch(step_, chunks * g);
  float* cells = lstm_ ? GrowScratch(cells_, rows * h) : nullptr;
  const float* bias_ih = parameters + offsets_.bias_ih;
  const float* bias_hh = parameters + offsets_.bias_hh;
  for (int64_t r = 0; r < rows; ++r) {
    std::copy(bias_ih, bias_ih + g, projected + r * g);
  }
  MultiplyByTransposed(rows, g, inputs_, encoded, inputs_,
                       parameters + offsets_.weight_ih, inputs_, 1.0f,
                       projected, g);
  for (int64_t t = 0; t < steps; ++t) {
    // The state each chunk's step reads: its start state, or the one the
    // previous step left.
    for (int64_t j = 0; j < chunks; ++j) {
      const int64_t row = t * chunks + j;
      float* into = read + row * s;
      if (starts[row] != 0) {
        std::fill(into, into + s, 0.0f);
      } else if (t == 0) {
        std::copy(states + j * s, states + (j + 1) * s, into);
      } else {
        const int64_t before = row - chunks;
        std::copy(features + before * h, features + (before + 1) * h, into);
        if (lstm_) {
          std::copy(cells + before * h, cells + (before + 1) * h, into + h);
        }
      }
      std::copy(bias_hh, bias_hh + g, step + j * g);
    }
    MultiplyByTransposed(chunks, g, h, read + t * chunks * s, s,
                         parameters + offsets_.weight_hh, h, 1.0f, step, g);
    for (int64_t j = 0; j < chunks; ++j) {
      const int64_t row = t * chunks + j;
      const float* x = projected + row * g;
      const float* p = step + j * g;
      const float* state = read + row * s;
      float* a = activations + row * g;
      float* e = extra + row * h;
      float* out = features + row * h;
      if (!lstm_) {
        for (int64_t k = 0; k < h; ++k) {
          a[k] = Sigmoid(x[k] + p[k]);
          a[h + k] = Sigmoid(x[h + k] + p[h + k]);
          e[k] = p[2 * h + k];
          a[2 * h + k] = std::tanh(x[2 * h + k] + a[k] * e[k]);
          out[k] = (1.0f - a[h + k]) * a[2 * h + k] + a[h + k] * state[k];
        }
      } else {
        float* cell = cells + row * h;
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
    }
  }
}

void FlatRecurrentCore::Backward(const float* parameters,
                                 const float* d_features, float* gradients,
                                 float* d_encoded) {
  const int64_t chunks = chunks_;
  const int64_t rows = steps_ * chunks;
  const int64_t g = gates();
  const int64_t h = hidden_;
  const int64_t s = state_size();
  float* d_weight_hh = gradients + offsets_.weight_hh;
  float* d_bias_hh = gradients + offsets_.bias_hh;
  float* d_bias_ih = gradients + offsets_.bias_ih;
  std::fill(d_weight_hh, d_weight_hh + g * h, 0.0f);
  std::fill(d_bias_hh, d_bias_hh + g, 0.0f);
  std::fill(d_bias_ih, d_bias_ih + g, 0.0f);
  // Per row, the gradient of the gates' pre-activations through the input
  // projection; per chunk, through the hidden one (the GRU's candidate
  // takes r times its hidden term).
  float* from_input = GrowScratch(gate_gradients_, rows * g);
  float* from_hidden = GrowScratch(step_, chunks * g);
  float* carry = GrowScratch(carry_, chunks * s);
  float* next = GrowScratch(next_carry_, chunks * s);
  std::fill(carry, carry + chunks * s, 0.0f);
  for (int64_t t = steps_; t-- > 0;) {
    for (int64_t j = 0; j < chunks; ++j) {
      const int64_t row = t * chunks + j;
      const float* a = activations_.data() + row * g;
      const float* e = extra_.data() + row * h;
      const float* state = read_.data() + row * s;
      float* gx = from_input + row * g;
      float* gh = from_hidden + j * g;
      float* into = next + j * s;
      for (int64_t k = 0; k < h; ++k) {
        const float dh = d_features[row * h + k] + carry[j * s + k];
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
          const float i = a[k], f = a[h + k], c = a[2 * h + k],
                      o = a[3 * h + k];
          const float dc = carry[j * s + h + k] + dh * o * (1.0f - e[k] * e[k]);
          gx[k] = gh[k] = dc * c * i * (1.0f - i);
          gx[h + k] = gh[h + k] = dc * state[h + k] * f * (1.0f - f);
          gx[2 * h + k] = gh[2 * h + k] = dc * i * (1.0f - c * c);
          gx[3 * h + k] = gh[3 * h + k] = dh * e[k] * o * (1.0f - o);
          into[k] = 0.0f;
          into[h + k] = dc * f;
        }
      }
    }
    // dW_hh += G_h^T h_read; the read hidden states get G_h W_hh.
    cblas_sgemm(CblasRowMajor, CblasTrans, CblasNoTrans, static_cast<int>(g),
                static_cast<int>(h), static_cast<int>(chunks), 1.0f,
                from_hidden, static_cast<int>(g), read_.data() + t * chunks * s,
                static_cast<int>(s), 1.0f, d_weight_hh, static_cast<int>(h));
    AddColumnSums(from_hidden, chunks, g, d_bias_hh);
    cblas_sgemm(CblasRowMajor, CblasNoTrans, CblasNoTrans,
                static_cast<int>(chunks), static_cast<int>(h),
                static_cast<int>(g), 1.0f, from_hidden, static_cast<int>(g),
                parameters + offsets_.weight_hh, static_cast<int>(h), 1.0f,
                next, static_cast<int>(s));
    // A state zeroed at an episode start passes nothing back.
    for (int64_t j = 0; j < chunks; ++j) {
      const bool start = starts_[t * chunks + j] != 0;
      for (int64_t k = 0; k < s; ++k) {
        carry[j * s + k] = start ? 0.0f : next[j * s + k];
      }
    }
  }
  // The input projections of every step at once.
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

}  // namespace vantage
