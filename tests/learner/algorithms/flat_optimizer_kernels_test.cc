#include "learner/algorithms/flat_optimizer_kernels.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "gtest/gtest.h"

// The references below are the plain scalar loops, compiled as the rest of
// the project is; the kernels must round every element as they do.
#pragma STDC FP_CONTRACT OFF

namespace vantage {
namespace {

struct Arrays {
  std::vector<float> parameters, gradients, first, second;
};

// Not a multiple of any vector width, so that every kernel's tail runs;
// gradients of every scale, exact zeros and one subnormal among them.
Arrays RandomArrays(uint32_t seed, bool second_positive) {
  constexpr int kSize = 1027;
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal;
  std::uniform_int_distribution<int> exponent(-30, 10);
  Arrays a;
  for (int i = 0; i < kSize; ++i) {
    a.parameters.push_back(normal(rng));
    a.gradients.push_back(std::ldexp(normal(rng), exponent(rng)));
    a.first.push_back(0.1f * normal(rng));
    const float square = std::ldexp(std::abs(normal(rng)), exponent(rng));
    a.second.push_back(second_positive ? square : 0.0f);
  }
  a.gradients[3] = 0.0f;
  a.gradients[500] = std::numeric_limits<float>::denorm_min();
  a.second[7] = 0.0f;
  return a;
}

bool BitEqual(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

void ReferenceAdam(const AdamCoefficients& c, Arrays& a) {
  for (size_t i = 0; i < a.parameters.size(); ++i) {
    const float g = a.gradients[i];
    a.first[i] = a.first[i] * c.beta1 + c.one_minus_beta1 * g;
    a.second[i] = a.second[i] * c.beta2 + c.one_minus_beta2 * g * g;
    const float denominator =
        std::sqrt(a.second[i]) / c.correction2_sqrt + c.eps;
    a.parameters[i] -= c.step_size * (a.first[i] / denominator);
  }
}

void ReferenceRmsprop(float alpha, float eps, float minus_lr, bool eps_inside,
                      Arrays& a) {
  for (size_t i = 0; i < a.parameters.size(); ++i) {
    const float g = a.gradients[i];
    a.second[i] = a.second[i] * alpha + (1.0f - alpha) * g * g;
    const float root = eps_inside ? std::sqrt(a.second[i] + eps)
                                  : std::sqrt(a.second[i]) + eps;
    a.parameters[i] += minus_lr * g / root;
  }
}

TEST(FlatOptimizerKernelsTest, AdamRoundsEveryElementAsTheScalarLoop) {
  for (int step : {1, 2, 50}) {
    AdamCoefficients c;
    c.beta1 = 0.9f;
    c.beta2 = 0.999f;
    c.one_minus_beta1 = static_cast<float>(1.0 - 0.9);
    c.one_minus_beta2 = static_cast<float>(1.0 - 0.999);
    c.correction2_sqrt =
        static_cast<float>(std::sqrt(1.0 - std::pow(0.999, step)));
    c.eps = 1e-8f;
    c.step_size = static_cast<float>(3e-4 / (1.0 - std::pow(0.9, step)));
    Arrays kernel = RandomArrays(step, /*second_positive=*/step > 1);
    Arrays reference = kernel;
    for (int repeat = 0; repeat < 3; ++repeat) {
      AdamKernel(c, static_cast<int64_t>(kernel.parameters.size()),
                 kernel.parameters.data(), kernel.gradients.data(),
                 kernel.first.data(), kernel.second.data());
      ReferenceAdam(c, reference);
    }
    EXPECT_TRUE(BitEqual(kernel.parameters, reference.parameters)) << step;
    EXPECT_TRUE(BitEqual(kernel.first, reference.first)) << step;
    EXPECT_TRUE(BitEqual(kernel.second, reference.second)) << step;
  }
}

TEST(FlatOptimizerKernelsTest, RmspropRoundsEveryElementAsTheScalarLoop) {
  for (bool eps_inside : {false, true}) {
    const float alpha = 0.99f;
    const float eps = 1e-5f;
    const float minus_lr = -7e-4f;
    Arrays kernel = RandomArrays(11, /*second_positive=*/!eps_inside);
    Arrays reference = kernel;
    for (int repeat = 0; repeat < 3; ++repeat) {
      RmspropKernel(alpha, 1.0f - alpha, eps, minus_lr, eps_inside,
                    static_cast<int64_t>(kernel.parameters.size()),
                    kernel.parameters.data(), kernel.gradients.data(),
                    kernel.second.data());
      ReferenceRmsprop(alpha, eps, minus_lr, eps_inside, reference);
    }
    EXPECT_TRUE(BitEqual(kernel.parameters, reference.parameters))
        << eps_inside;
    EXPECT_TRUE(BitEqual(kernel.second, reference.second)) << eps_inside;
  }
}

}  // namespace
}  // namespace vantage
