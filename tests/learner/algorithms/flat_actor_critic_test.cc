#include "learner/algorithms/flat_actor_critic.h"

#include <ATen/ATen.h>
#include <torch/optim/adam.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/nn/distributions.h"
#include "common/nn/networks.h"
#include "gtest/gtest.h"
#include "learner/algorithms/flat_adam.h"
#include "tests/fakes/vector_spec.h"

namespace vantage {
namespace {

// Random actions [rows, heads] (indices as floats) of `spec`'s heads.
at::Tensor RandomActions(const EnvSpec& spec, int64_t rows) {
  std::vector<at::Tensor> values;
  for (int64_t choices : spec.action_heads()) {
    values.push_back(at::randint(0, choices, {rows}));
  }
  return at::stack(values, 1).to(at::kFloat);
}

// Random masks [rows, action_size] as uint8 under which each row's action
// ([rows, heads]) is legal in every head.
at::Tensor MasksAllowing(const EnvSpec& spec, const at::Tensor& actions) {
  at::Tensor masks = at::rand({actions.size(0), spec.action_size}) < 0.4;
  int64_t offset = 0;
  const std::vector<int64_t> heads = spec.action_heads();
  for (size_t h = 0; h < heads.size(); offset += heads[h], ++h) {
    masks.scatter_(1, actions.select(1, h).to(at::kLong).unsqueeze(1) + offset,
                   true);
  }
  return masks.to(at::kByte).contiguous();
}

// Weights of the scale hidden layers start with (1 / sqrt(inputs)), for
// every layer, so that the outputs and the log-std are far from their
// initial zeros.
void Randomise(const std::vector<at::Tensor>& parameters) {
  at::NoGradGuard no_grad;
  for (at::Tensor parameter : parameters) {
    const double scale =
        parameter.dim() == 2 ? 1.0 / std::sqrt(parameter.size(1)) : 0.5;
    parameter.copy_(at::randn(parameter.sizes()) * scale);
  }
}

// Every element within `tolerance` of the largest magnitude of `reference`.
void ExpectClose(const float* fast, const at::Tensor& reference,
                 double tolerance, const std::string& what) {
  const at::Tensor expected = reference.detach().contiguous().reshape(-1);
  const double scale = std::max(1e-12, expected.abs().max().item<double>());
  double worst = 0.0;
  for (int64_t i = 0; i < expected.numel(); ++i) {
    worst = std::max(worst, std::abs(fast[i] - expected[i].item<double>()));
  }
  EXPECT_LE(worst / scale, tolerance) << what;
}

// After the flat networks' Forward and Backward: their log-probabilities,
// values and entropy are autograd's from the policy's `output` and the
// critic's `values`, and so is every parameter's gradient of
// sum(d_log_probs log_probs) + entropy_weight * entropy + sum(d_values
// values).
void ExpectAutogradsResults(const FlatActorCritic& flat,
                            PolicyNetworkImpl& policy, const at::Tensor& output,
                            const at::Tensor& actions, const at::Tensor& values,
                            const at::Tensor& d_log_probs,
                            double entropy_weight, const at::Tensor& d_values,
                            const std::vector<at::Tensor>& parameters) {
  const at::Tensor log_probs = policy.LogProb(output, actions);
  const at::Tensor entropy = policy.Entropy(output).mean();
  ExpectClose(flat.log_probs(), log_probs, 1e-6, "log-probabilities");
  ExpectClose(flat.values(), values, 1e-6, "values");
  EXPECT_NEAR(flat.mean_entropy(), entropy.item<double>(),
              1e-6 * std::max(1.0, std::abs(entropy.item<double>())));
  ((log_probs * d_log_probs).sum() + entropy_weight * entropy +
   (values * d_values).sum())
      .backward();
  for (size_t i = 0; i < parameters.size(); ++i) {
    ExpectClose(flat.gradients() + flat.offsets()[i], parameters[i].grad(),
                1e-5, "the gradient of parameter " + std::to_string(i));
  }
}

struct Case {
  bool discrete;
  int64_t observations;
  int64_t actions;
  std::vector<int64_t> hidden;
  bool bytes;
  bool masked = false;             // discrete only: action masks
  std::vector<int64_t> nvec = {};  // MultiDiscrete heads (sum: actions)
};

class FlatActorCriticTest : public ::testing::TestWithParam<Case> {};

TEST_P(FlatActorCriticTest, ForwardAndGradientsAreAutograds) {
  const Case& c = GetParam();
  at::manual_seed(3);
  EnvSpec spec = VectorSpec(c.discrete, c.observations, c.actions);
  spec.action_nvec = c.nvec;
  if (c.bytes) {
    spec.observation_shape = {c.observations};
    spec.observation_high = 7;
  }
  NetworkConfig config;
  config.hidden = c.hidden;
  PolicyNetwork policy(spec, config);
  ValueNetwork value = MakeValueNetwork(spec, config, *policy);
  const std::vector<at::Tensor> parameters = NetworkParameters(*policy, *value);
  Randomise(parameters);
  absl::StatusOr<FlatActorCritic> flat =
      FlatActorCritic::Create(*policy, *value, parameters);
  ASSERT_TRUE(flat.ok()) << flat.status();

  constexpr int64_t kRows = 37;
  const at::Tensor observations =
      c.bytes ? at::randint(0, 8, {kRows, c.observations}, at::kByte)
              : at::randn({kRows, c.observations}) * 2.0;
  const at::Tensor actions =
      c.discrete ? RandomActions(spec, kRows) : at::randn({kRows, c.actions});
  const at::Tensor d_log_probs = at::randn({kRows});
  const at::Tensor d_values = at::randn({kRows});
  const double entropy_weight = -0.37;

  const at::Tensor masks =
      c.masked ? MasksAllowing(spec, actions) : at::Tensor();

  const at::Tensor inputs = flat->Inputs(observations);
  flat->Forward(inputs.data_ptr<float>(), actions.data_ptr<float>(), kRows,
                c.masked ? masks.data_ptr<uint8_t>() : nullptr);
  flat->Backward(d_log_probs.data_ptr<float>(), entropy_weight,
                 d_values.data_ptr<float>());

  const at::Tensor output =
      MaskLogits(policy->forward(observations),
                 c.masked ? masks.to(at::kBool) : at::Tensor());
  ExpectAutogradsResults(*flat, *policy, output, actions,
                         value->forward(observations), d_log_probs,
                         entropy_weight, d_values, parameters);
}

INSTANTIATE_TEST_SUITE_P(
    Heads, FlatActorCriticTest,
    ::testing::Values(Case{false, 17, 6, {64, 64}, false},
                      Case{true, 11, 5, {32}, false},
                      Case{false, 3, 1, {}, false},
                      Case{true, 9, 4, {16, 8}, true},
                      Case{true, 11, 5, {32}, false, true},
                      Case{true, 9, 4, {16, 8}, true, true},
                      Case{true, 8, 9, {16}, false, false, {2, 4, 3}},
                      Case{true, 8, 7, {}, false, true, {3, 4}}));

struct RecurrentCase {
  Core core;
  bool discrete;
  std::vector<int64_t> hidden;
  bool masked = false;  // discrete only: action masks
  bool multi = false;   // MultiDiscrete heads of 2 and 3 choices
};

class FlatRecurrentTest : public ::testing::TestWithParam<RecurrentCase> {};

// A recurrent trunk over chunks: 7 steps of 5 chunks from random start
// states, episodes starting inside some: the log-probabilities, values and
// entropy, and every parameter's gradient through time, against autograd
// through RecurrentTrunkImpl::Unroll.
TEST_P(FlatRecurrentTest, SequencesAndGradientsThroughTimeAreAutograds) {
  const RecurrentCase& c = GetParam();
  at::manual_seed(5);
  EnvSpec spec = VectorSpec(c.discrete, 6, 3);
  if (c.multi) {
    spec.action_size = 5;
    spec.action_nvec = {2, 3};
  }
  NetworkConfig config;
  config.hidden = c.hidden;
  config.core = c.core;
  config.core_size = 12;
  PolicyNetwork policy(spec, config);
  ValueNetwork value = MakeValueNetwork(spec, config, *policy);
  const std::vector<at::Tensor> parameters = NetworkParameters(*policy, *value);
  Randomise(parameters);
  absl::StatusOr<FlatActorCritic> flat =
      FlatActorCritic::Create(*policy, *value, parameters);
  ASSERT_TRUE(flat.ok()) << flat.status();
  ASSERT_TRUE(flat->recurrent());
  ASSERT_EQ(flat->state_size(), config.core_state_size());

  constexpr int64_t kSteps = 7;
  constexpr int64_t kChunks = 5;
  constexpr int64_t kRows = kSteps * kChunks;
  const at::Tensor observations = at::randn({kRows, 6}) * 2.0;
  const at::Tensor actions =
      c.discrete ? RandomActions(spec, kRows) : at::randn({kRows, 3});
  const at::Tensor starts = at::rand({kSteps, kChunks}) < 0.2;
  const at::Tensor states = at::randn({kChunks, flat->state_size()}) * 0.5;
  const at::Tensor start_bytes = starts.to(at::kByte).reshape({-1});
  const at::Tensor d_log_probs = at::randn({kRows});
  const at::Tensor d_values = at::randn({kRows});
  const double entropy_weight = -0.37;
  const at::Tensor masks =
      c.masked ? MasksAllowing(spec, actions) : at::Tensor();

  const at::Tensor inputs = flat->Inputs(observations);
  flat->ForwardSequences(inputs.data_ptr<float>(), actions.data_ptr<float>(),
                         start_bytes.data_ptr<uint8_t>(),
                         states.data_ptr<float>(), kSteps, kChunks,
                         c.masked ? masks.data_ptr<uint8_t>() : nullptr);
  flat->Backward(d_log_probs.data_ptr<float>(), entropy_weight,
                 d_values.data_ptr<float>());

  RecurrentTrunk trunk = policy->trunk();
  const at::Tensor features = trunk->Unroll(observations, starts, states);
  ExpectAutogradsResults(
      *flat, *policy,
      MaskLogits(policy->Head(features),
                 c.masked ? masks.to(at::kBool) : at::Tensor()),
      actions, value->Head(features), d_log_probs, entropy_weight, d_values,
      parameters);
}

INSTANTIATE_TEST_SUITE_P(
    Cores, FlatRecurrentTest,
    ::testing::Values(RecurrentCase{Core::kGru, false, {16, 8}},
                      RecurrentCase{Core::kGru, true, {}},
                      RecurrentCase{Core::kLstm, false, {16}},
                      RecurrentCase{Core::kLstm, true, {8, 8}},
                      RecurrentCase{Core::kGru, true, {16}, true},
                      RecurrentCase{Core::kLstm, true, {8}, true, true}));

TEST(FlatActorCriticTest, PushWritesTheModulesAndPullReadsThem) {
  at::manual_seed(4);
  const EnvSpec spec = VectorSpec(false, 5, 2);
  NetworkConfig config;
  PolicyNetwork policy(spec, config);
  ValueNetwork value = MakeValueNetwork(spec, config, *policy);
  const std::vector<at::Tensor> parameters = NetworkParameters(*policy, *value);
  absl::StatusOr<FlatActorCritic> flat =
      FlatActorCritic::Create(*policy, *value, parameters);
  ASSERT_TRUE(flat.ok()) << flat.status();
  for (int64_t i = 0; i < flat->size(); ++i) flat->parameters()[i] = i;
  flat->Push();
  for (size_t p = 0; p < parameters.size(); ++p) {
    EXPECT_EQ(parameters[p].reshape(-1)[0].item<float>(),
              static_cast<float>(flat->offsets()[p]));
  }
  Randomise(parameters);
  flat->Pull();
  for (size_t p = 0; p < parameters.size(); ++p) {
    EXPECT_EQ(flat->parameters()[flat->offsets()[p]],
              parameters[p].reshape(-1)[0].item<float>());
  }
}

TEST(FlatActorCriticTest, AConvolutionalTorsoIsLeftToAutograd) {
  EnvSpec spec = VectorSpec(true, 10 * 10 * 4, 3);
  spec.observation_shape = {4, 10, 10};
  spec.observation_high = 1;
  for (bool shared : {false, true}) {
    NetworkConfig config;
    config.torso = Torso::kMinAtar;
    config.shared_torso = shared;
    PolicyNetwork policy(spec, config);
    ValueNetwork value = MakeValueNetwork(spec, config, *policy);
    absl::StatusOr<FlatActorCritic> flat = FlatActorCritic::Create(
        *policy, *value, NetworkParameters(*policy, *value));
    ASSERT_FALSE(flat.ok());
    EXPECT_EQ(flat.status().code(), absl::StatusCode::kUnimplemented);
    EXPECT_NE(flat.status().message().find("convolutional"), std::string::npos)
        << flat.status();
  }
}

TEST(FlatAdamTest, StepsAsTorchAdamAndCarriesItsState) {
  at::manual_seed(6);
  std::vector<at::Tensor> reference = {at::randn({4, 3}), at::randn({5})};
  std::vector<at::Tensor> tensors = {reference[0].clone(),
                                     reference[1].clone()};
  for (at::Tensor& t : reference) t.set_requires_grad(true);
  torch::optim::Adam torch_adam(reference,
                                torch::optim::AdamOptions(3e-3).eps(1e-5));
  torch::optim::Adam holder(tensors, torch::optim::AdamOptions(3e-3).eps(1e-5));
  FlatAdam flat(tensors, {0, 12}, 17);
  std::vector<float> values(17), gradients(17);
  std::copy_n(tensors[0].data_ptr<float>(), 12, values.begin());
  std::copy_n(tensors[1].data_ptr<float>(), 5, values.begin() + 12);
  for (int step = 0; step < 25; ++step) {
    const at::Tensor g0 = at::randn({4, 3}) * (step % 3 == 0 ? 1e-3 : 1.0);
    const at::Tensor g1 = at::randn({5});
    reference[0].mutable_grad() = g0.clone();
    reference[1].mutable_grad() = g1.clone();
    torch_adam.step();
    std::copy_n(g0.data_ptr<float>(), 12, gradients.begin());
    std::copy_n(g1.data_ptr<float>(), 5, gradients.begin() + 12);
    flat.Step(holder, values.data(), gradients.data());
  }
  ExpectClose(values.data(), reference[0], 1e-6, "first tensor");
  ExpectClose(values.data() + 12, reference[1], 1e-6, "second tensor");

  // Through the torch optimiser's state and back, nothing changes.
  flat.StoreInto(holder);
  FlatAdam restored(tensors, {0, 12}, 17);
  ASSERT_TRUE(restored.LoadFrom(holder).ok());
  std::vector<float> a = values, b = values;
  for (float& g : gradients) g = 0.25f;
  flat.Step(holder, a.data(), gradients.data());
  restored.Step(holder, b.data(), gradients.data());
  EXPECT_EQ(a, b);
}

}  // namespace
}  // namespace vantage
