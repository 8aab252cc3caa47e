#include "common/nn/cpu_sampling.h"

#include <ATen/CPUGeneratorImpl.h>
#include <ATen/core/DistributionsHelper.h>

#include <cmath>
#include <mutex>

namespace vantage {
namespace {

// The Box-Muller step of LibTorch's float normal fill: 16 uniforms in
// [0, 1) become 16 normals, pairing slot j with slot j + 8.
void BoxMuller16(float* data) {
  constexpr float kTwoPi = 6.283185307179586f;
  for (int j = 0; j < 8; ++j) {
    const float u1 = 1.0f - data[j];  // (0, 1] for the log
    const float u2 = data[j + 8];
    const float radius = std::sqrt(-2.0f * std::log(u1));
    const float theta = kTwoPi * u2;
    data[j] = radius * std::cos(theta);
    data[j + 8] = radius * std::sin(theta);
  }
}

}  // namespace

void FillStandardNormal(at::Generator& generator, float* out, int64_t n) {
  auto* cpu = at::check_generator<at::CPUGeneratorImpl>(generator);
  std::lock_guard<std::mutex> lock(generator.mutex());
  if (n < 16) {
    // Element by element in double, keeping the second value of each
    // pair in the generator for the next draw.
    at::normal_distribution<double> normal(0.0, 1.0);
    for (int64_t i = 0; i < n; ++i) out[i] = static_cast<float>(normal(cpu));
    return;
  }
  at::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  for (int64_t i = 0; i < n; ++i) out[i] = uniform(cpu);
  for (int64_t i = 0; i + 16 <= n; i += 16) BoxMuller16(out + i);
  if (n % 16 != 0) {
    // The last 16 again, from new uniforms.
    float* tail = out + n - 16;
    for (int i = 0; i < 16; ++i) tail[i] = uniform(cpu);
    BoxMuller16(tail);
  }
}

void SampleCategorical(at::Generator& generator, const float* probabilities,
                       int64_t rows, int64_t n, int64_t* out) {
  auto* cpu = at::check_generator<at::CPUGeneratorImpl>(generator);
  std::lock_guard<std::mutex> lock(generator.mutex());
  at::exponential_distribution<double> exponential(1.0);
  for (int64_t r = 0; r < rows; ++r) {
    const float* p = probabilities + r * n;
    int64_t best = 0;
    float best_ratio = 0.0f;
    for (int64_t i = 0; i < n; ++i) {
      const float q = static_cast<float>(exponential(cpu));
      const float ratio = p[i] / q;
      // argmax keeps the first of equal values.
      if (i == 0 || ratio > best_ratio) {
        best = i;
        best_ratio = ratio;
      }
    }
    out[r] = best;
  }
}

}  // namespace vantage
