#include "common/nn/mlp_policy_kernel.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/nn/cpu_sampling.h"
#include "common/nn/networks.h"
#include "common/nn/running_mean_std.h"
#include "gtest/gtest.h"
#include "tests/fakes/random_policy.h"
#include "tests/fakes/vector_spec.h"

namespace vantage {
namespace {

constexpr double kClip = 5.0;

// Observations as environments write them: doubles, some far enough out
// to be clipped; integers in range for byte observations.
std::vector<double> Observations(const EnvSpec& spec, int64_t rows) {
  at::Tensor values =
      spec.byte_observations()
          ? at::randint(0, spec.observation_high + 1,
                        {rows, spec.observation_size}, at::kDouble)
          : at::randn({rows, spec.observation_size}, at::kDouble) * 4.0;
  return std::vector<double>(values.data_ptr<double>(),
                             values.data_ptr<double>() + values.numel());
}

// |a - b| <= 1e-5 of b's scale (at least 1). Both sides sum floats, in
// orders that depend on the CPU's BLAS kernels: a Gaussian log-probability
// sums terms larger than itself, and two orders were seen 2.4e-6 apart at
// 1.86 (20 ulps). A wrong formula, normaliser or clip is off by far more.
void ExpectClose(const std::vector<float>& fast, const at::Tensor& reference,
                 const std::string& what) {
  const at::Tensor expected = reference.contiguous().to(at::kFloat).reshape(-1);
  ASSERT_EQ(static_cast<int64_t>(fast.size()), expected.numel()) << what;
  for (size_t i = 0; i < fast.size(); ++i) {
    const float want = expected[i].item<float>();
    EXPECT_LE(std::abs(fast[i] - want), 1e-5f * std::max(1.0f, std::abs(want)))
        << what << " [" << i << "]: " << fast[i] << " vs " << want;
  }
}

struct Case {
  bool discrete;
  int64_t observation_high;
  std::vector<int64_t> hidden;
  int64_t actions;
  std::vector<int64_t> nvec = {};  // MultiDiscrete heads (sum: actions)
};

// Several steps of acting at each batch size, from generators that start
// alike: outputs, actions and log-probabilities agree, and both generators
// end in the same place.
void CompareWithLibTorch(const Case& c) {
  EnvSpec spec = VectorSpec(c.discrete, 7, c.actions);
  spec.observation_high = c.observation_high;
  spec.action_nvec = c.nvec;
  NetworkConfig config;
  config.hidden = c.hidden;
  PolicyNetwork policy(spec, config);
  RunningMeanStd normalizer(spec.observation_size);
  RandomisePolicy(*policy, normalizer, spec);
  absl::StatusOr<MlpPolicyKernel> kernel =
      MlpPolicyKernel::Create(spec, *policy, normalizer, kClip);
  ASSERT_TRUE(kernel.ok()) << kernel.status();
  ASSERT_EQ(kernel->output_size(), c.actions);

  at::Generator reference = at::make_generator<at::CPUGeneratorImpl>(11);
  at::Generator fast = at::make_generator<at::CPUGeneratorImpl>(11);
  at::NoGradGuard no_grad;
  // 1 (a matrix-vector product), sizes below and above LibTorch's 16
  // values for the normal fill, and one with a tail.
  for (int64_t rows : {1, 1, 2, 3, 5, 16, 1}) {
    const std::string what = "rows " + std::to_string(rows);
    const std::vector<double> observations = Observations(spec, rows);
    const at::Tensor output = policy->forward(ObservationsForNetwork(
        spec, normalizer, ObservationTensor(spec, observations.data(), rows),
        kClip));
    std::vector<float> outputs(rows * c.actions);
    kernel->Forward(observations.data(), rows, outputs.data());
    ExpectClose(outputs, output, what + " outputs");

    const at::Tensor action = policy->Act(output, false, reference);
    const at::Tensor log_prob = policy->LogProb(output, action);
    std::vector<float> actions(rows * kernel->action_width());
    std::vector<float> log_probs(rows);
    kernel->Act(outputs.data(), rows, fast, actions.data(), log_probs.data());
    ExpectClose(actions, action, what + " actions");
    ExpectClose(log_probs, log_prob, what + " log-probs");
  }
  EXPECT_TRUE(at::equal(at::randint(1 << 30, {8}, reference),
                        at::randint(1 << 30, {8}, fast)))
      << "the generators drew different amounts";
}

// A recurrent policy over 50 steps at each of several batch sizes: the
// states the kernel carries stay with LibTorch's (PolicyNetworkImpl::Step),
// rows zeroed on both sides where an episode starts, and the outputs,
// actions and log-probabilities agree.
void CompareRecurrentWithLibTorch(Core core, const Case& c) {
  EnvSpec spec = VectorSpec(c.discrete, 7, c.actions);
  spec.action_nvec = c.nvec;
  NetworkConfig config;
  config.hidden = c.hidden;
  config.core = core;
  config.core_size = 24;
  PolicyNetwork policy(spec, config);
  RunningMeanStd normalizer(spec.observation_size);
  RandomisePolicy(*policy, normalizer, spec);
  absl::StatusOr<MlpPolicyKernel> kernel =
      MlpPolicyKernel::Create(spec, *policy, normalizer, kClip);
  ASSERT_TRUE(kernel.ok()) << kernel.status();
  ASSERT_EQ(kernel->state_size(), config.core_state_size());
  at::Generator reference = at::make_generator<at::CPUGeneratorImpl>(11);
  at::Generator fast = at::make_generator<at::CPUGeneratorImpl>(11);
  at::NoGradGuard no_grad;
  for (int64_t rows : {1, 3, 16}) {
    at::Tensor state = at::randn({rows, kernel->state_size()}) * 0.5;
    std::vector<float> states(state.data_ptr<float>(),
                              state.data_ptr<float>() + state.numel());
    for (int step = 0; step < 50; ++step) {
      const std::string what =
          "rows " + std::to_string(rows) + " step " + std::to_string(step);
      if (step % 7 == 3) {
        const int64_t row = step % rows;
        state[row].zero_();
        std::fill_n(states.begin() + row * kernel->state_size(),
                    kernel->state_size(), 0.0f);
      }
      const std::vector<double> observations = Observations(spec, rows);
      const at::Tensor output = policy->Step(
          ObservationsForNetwork(
              spec, normalizer,
              ObservationTensor(spec, observations.data(), rows), kClip),
          state);
      std::vector<float> outputs(rows * c.actions);
      kernel->Forward(observations.data(), rows, outputs.data(), states.data());
      ExpectClose(outputs, output, what + " outputs");
      ExpectClose(states, state, what + " states");
      const at::Tensor action = policy->Act(output, false, reference);
      std::vector<float> actions(rows * kernel->action_width());
      std::vector<float> log_probs(rows);
      kernel->Act(outputs.data(), rows, fast, actions.data(), log_probs.data());
      ExpectClose(actions, action, what + " actions");
      ExpectClose(log_probs, policy->LogProb(output, action),
                  what + " log-probs");
      if (::testing::Test::HasFailure()) return;
    }
  }
}

TEST(MlpPolicyKernelTest, AGruPolicyAgreesWithLibTorch) {
  CompareRecurrentWithLibTorch(Core::kGru, {false, 0, {32, 16}, 3});
  CompareRecurrentWithLibTorch(Core::kGru, {true, 0, {}, 4});
}

TEST(MlpPolicyKernelTest, AnLstmPolicyAgreesWithLibTorch) {
  CompareRecurrentWithLibTorch(Core::kLstm, {false, 0, {16}, 2});
  CompareRecurrentWithLibTorch(Core::kLstm, {true, 0, {32, 32}, 5});
}

TEST(MlpPolicyKernelTest, GaussianTwoHiddenLayersAgreesWithLibTorch) {
  CompareWithLibTorch({false, 0, {64, 64}, 6});
}

TEST(MlpPolicyKernelTest, GaussianOneHiddenLayerAgreesWithLibTorch) {
  CompareWithLibTorch({false, 0, {32}, 3});
}

TEST(MlpPolicyKernelTest, LinearGaussianAgreesWithLibTorch) {
  CompareWithLibTorch({false, 0, {}, 1});
}

TEST(MlpPolicyKernelTest, CategoricalAgreesWithLibTorch) {
  CompareWithLibTorch({true, 0, {64, 64}, 5});
}

// MultiDiscrete: head by head, each over every row, the same draws as
// LibTorch's; log-probabilities summed over the heads.
TEST(MlpPolicyKernelTest, MultiDiscreteAgreesWithLibTorch) {
  CompareWithLibTorch({true, 0, {32}, 9, {2, 4, 3}});
  CompareRecurrentWithLibTorch(Core::kGru, {true, 0, {16}, 7, {5, 2}});
}

TEST(MlpPolicyKernelTest, ByteObservationsAgreeWithLibTorch) {
  CompareWithLibTorch({true, 9, {16}, 4});
  CompareWithLibTorch({false, 255, {16}, 2});
}

TEST(MlpPolicyKernelTest, StandardNormalsAreLibTorchs) {
  for (int64_t n : {1, 5, 15, 16, 17, 40, 64}) {
    at::Generator a = at::make_generator<at::CPUGeneratorImpl>(3);
    at::Generator b = at::make_generator<at::CPUGeneratorImpl>(3);
    // Twice, so the normal LibTorch keeps for the next draw is used too.
    for (int round = 0; round < 2; ++round) {
      const at::Tensor expected = at::normal(0.0, 1.0, {n}, a, at::kFloat);
      std::vector<float> values(n);
      FillStandardNormal(b, values.data(), n);
      ExpectClose(values, expected, "n " + std::to_string(n));
    }
  }
}

TEST(MlpPolicyKernelTest, CategoricalDrawsAreLibTorchs) {
  at::Generator a = at::make_generator<at::CPUGeneratorImpl>(5);
  at::Generator b = at::make_generator<at::CPUGeneratorImpl>(5);
  const at::Tensor probabilities = at::softmax(at::randn({64, 6}), -1);
  const at::Tensor expected = at::multinomial(probabilities, 1, false, a);
  std::vector<int64_t> indices(64);
  SampleCategorical(b, probabilities.data_ptr<float>(), 64, 6, indices.data());
  for (int64_t r = 0; r < 64; ++r) {
    EXPECT_EQ(indices[r], expected[r][0].item<int64_t>()) << "row " << r;
  }
}

TEST(MlpPolicyKernelTest, AConvolutionalTorsoIsLeftToLibTorch) {
  EnvSpec spec = VectorSpec(true, 10 * 10 * 4, 3);
  spec.observation_shape = {4, 10, 10};
  spec.observation_high = 1;
  NetworkConfig config;
  config.torso = Torso::kMinAtar;
  PolicyNetwork policy(spec, config);
  RunningMeanStd normalizer(spec.observation_size);
  absl::StatusOr<MlpPolicyKernel> kernel =
      MlpPolicyKernel::Create(spec, *policy, normalizer, kClip);
  ASSERT_FALSE(kernel.ok());
  EXPECT_EQ(kernel.status().code(), absl::StatusCode::kUnimplemented);
  EXPECT_NE(kernel.status().message().find("convolutional"), std::string::npos)
      << kernel.status();
}

}  // namespace
}  // namespace vantage
