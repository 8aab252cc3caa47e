// The recurrent trunk's sequences against a reference written from the
// cells' equations: the same features, and the same gradients for every
// parameter and the start state, with episode starts zeroing the state on
// the way.

#include "common/nn/recurrent_trunk.h"

#include <ATen/ATen.h>

#include <vector>

#include "gtest/gtest.h"
#include "tests/fakes/vector_spec.h"

namespace vantage {
namespace {

constexpr int64_t kSteps = 9;
constexpr int64_t kRows = 4;

// One step from the equations (LibTorch's gate order) on `w`: weight_ih,
// weight_hh, bias_ih, bias_hh.
at::Tensor ReferenceStep(Core core, const std::vector<at::Tensor>& w,
                         const at::Tensor& x, const at::Tensor& state,
                         int64_t hidden) {
  const at::Tensor h = state.narrow(1, 0, hidden);
  const std::vector<at::Tensor> in =
      at::chunk(at::matmul(x, w[0].t()) + w[2], core == Core::kGru ? 3 : 4, 1);
  const std::vector<at::Tensor> from =
      at::chunk(at::matmul(h, w[1].t()) + w[3], core == Core::kGru ? 3 : 4, 1);
  if (core == Core::kGru) {
    const at::Tensor r = at::sigmoid(in[0] + from[0]);
    const at::Tensor z = at::sigmoid(in[1] + from[1]);
    const at::Tensor n = at::tanh(in[2] + r * from[2]);
    return (1 - z) * n + z * h;
  }
  const at::Tensor c = state.narrow(1, hidden, hidden);
  const at::Tensor i = at::sigmoid(in[0] + from[0]);
  const at::Tensor f = at::sigmoid(in[1] + from[1]);
  const at::Tensor g = at::tanh(in[2] + from[2]);
  const at::Tensor o = at::sigmoid(in[3] + from[3]);
  const at::Tensor next_c = f * c + i * g;
  return at::cat({o * at::tanh(next_c), next_c}, 1);
}

void ExpectSameSequences(Core core) {
  at::manual_seed(core == Core::kGru ? 3 : 4);
  const EnvSpec spec = VectorSpec(false, 5, 2);
  NetworkConfig config;
  config.hidden = {8};
  config.core = core;
  config.core_size = 6;
  RecurrentTrunk trunk(spec, config);
  const int64_t hidden = config.core_size;
  const at::Tensor observations = at::randn({kSteps * kRows, 5});
  const at::Tensor starts = at::rand({kSteps, kRows}) < 0.25;
  const at::Tensor state0 =
      (at::randn({kRows, trunk->state_size()}) * 0.5).requires_grad_();
  const at::Tensor weights = at::randn({kSteps * kRows, hidden});

  at::Tensor after;
  const at::Tensor features =
      trunk->Unroll(observations, starts, state0, &after);
  (features * weights).sum().backward();
  std::vector<at::Tensor> trunk_grads;
  for (const at::Tensor& p : trunk->parameters()) {
    trunk_grads.push_back(p.grad().clone());
  }
  const at::Tensor state_grad = state0.grad().clone();

  // The reference: the encoder through the trunk's own layers (the cells'
  // equations are what is under test), then the steps written out.
  std::vector<at::Tensor> params;
  for (const at::Tensor& p : trunk->parameters()) {
    params.push_back(p.detach().clone().requires_grad_());
  }
  const at::Tensor reference_state = state0.detach().clone().requires_grad_();
  const at::Tensor encoded =
      at::tanh(at::matmul(observations, params[0].t()) + params[1]);
  const std::vector<at::Tensor> cell(params.begin() + 2, params.end());
  at::Tensor state = reference_state;
  std::vector<at::Tensor> reference_features, reference_after;
  for (int64_t t = 0; t < kSteps; ++t) {
    state = at::where(starts[t].unsqueeze(1), at::zeros_like(state), state);
    state =
        ReferenceStep(core, cell, encoded.slice(0, t * kRows, (t + 1) * kRows),
                      state, hidden);
    reference_features.push_back(state.narrow(1, 0, hidden));
    reference_after.push_back(state);
  }
  const at::Tensor reference = at::cat(reference_features);
  (reference * weights).sum().backward();

  EXPECT_TRUE(at::allclose(features, reference, 1e-5, 1e-6));
  EXPECT_TRUE(at::allclose(after, at::stack(reference_after), 1e-5, 1e-6));
  ASSERT_EQ(trunk_grads.size(), params.size());
  for (size_t i = 0; i < params.size(); ++i) {
    EXPECT_TRUE(at::allclose(trunk_grads[i], params[i].grad(), 1e-4, 1e-6))
        << "parameter " << i << ": "
        << (trunk_grads[i] - params[i].grad()).abs().max().item<float>();
  }
  EXPECT_TRUE(at::allclose(state_grad, reference_state.grad(), 1e-4, 1e-6));
  // Rows whose episode starts before anything reads the start state get
  // no gradient into it.
  for (int64_t n = 0; n < kRows; ++n) {
    if (starts[0][n].item<bool>()) {
      EXPECT_EQ(state_grad[n].abs().max().item<float>(), 0.0f);
    }
  }
}

TEST(RecurrentTrunkTest, AGruUnrollsAsItsEquations) {
  ExpectSameSequences(Core::kGru);
}

TEST(RecurrentTrunkTest, AnLstmUnrollsAsItsEquations) {
  ExpectSameSequences(Core::kLstm);
}

// Step by step from zero states is the same as one unroll.
TEST(RecurrentTrunkTest, StepsAgreeWithAnUnroll) {
  const EnvSpec spec = VectorSpec(true, 5, 3);
  NetworkConfig config;
  config.hidden = {};
  config.core = Core::kLstm;
  config.core_size = 4;
  RecurrentTrunk trunk(spec, config);
  at::NoGradGuard no_grad;
  const at::Tensor observations = at::randn({6 * 2, 5});
  const at::Tensor features = trunk->Unroll(
      observations, at::zeros({6, 2}, at::kBool), trunk->InitialState(2));
  at::Tensor state = trunk->InitialState(2);
  for (int64_t t = 0; t < 6; ++t) {
    state = trunk->Step(trunk->Encode(observations.slice(0, 2 * t, 2 * t + 2)),
                        state);
    EXPECT_TRUE(
        at::equal(trunk->Hidden(state), features.slice(0, 2 * t, 2 * t + 2)));
  }
}

// The critic's pass without autograd is the unroll, up to float rounding,
// with episodes starting on the way.
TEST(RecurrentTrunkTest, UnrollingWithoutGradientsAgrees) {
  for (Core core : {Core::kGru, Core::kLstm}) {
    at::manual_seed(6);
    const EnvSpec spec = VectorSpec(false, 5, 2);
    NetworkConfig config;
    config.hidden = {8};
    config.core = core;
    config.core_size = 6;
    RecurrentTrunk trunk(spec, config);
    const at::Tensor observations = at::randn({kSteps * kRows, 5});
    const at::Tensor starts = at::rand({kSteps, kRows}) < 0.25;
    const at::Tensor state = at::randn({kRows, trunk->state_size()}) * 0.5;
    at::NoGradGuard no_grad;
    at::Tensor after, fast_after;
    const at::Tensor features =
        trunk->Unroll(observations, starts, state, &after);
    const at::Tensor fast =
        trunk->UnrollWithoutGradients(observations, starts, state, &fast_after);
    EXPECT_TRUE(at::allclose(fast, features, 1e-5, 1e-6));
    EXPECT_TRUE(at::allclose(fast_after, after, 1e-5, 1e-6));
  }
}

}  // namespace
}  // namespace vantage
