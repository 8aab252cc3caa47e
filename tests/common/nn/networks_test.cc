#include "common/nn/networks.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>

#include <cmath>

#include "common/nn/distributions.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

EnvSpec ContinuousSpec() {
  EnvSpec spec;
  spec.name = "test";
  spec.observation_size = 5;
  spec.action_size = 3;
  spec.action_low.assign(3, -1.0);
  spec.action_high.assign(3, 1.0);
  return spec;
}

TEST(NetworksTest, OrthogonalInitialisationWithTheBaselinesGains) {
  at::manual_seed(0);
  PolicyNetwork policy(ContinuousSpec(), NetworkConfig{{64, 64}});
  const auto parameters = policy->named_parameters();
  // First hidden layer [64, 5]: orthonormal columns scaled by sqrt(2).
  const at::Tensor w0 = parameters["body.layers.0.weight"];
  EXPECT_TRUE(at::allclose(w0.t().matmul(w0), 2.0 * at::eye(5), 1e-4, 1e-4));
  // Output layer [3, 64]: orthonormal rows scaled by 0.01.
  const at::Tensor w2 = parameters["body.layers.2.weight"];
  EXPECT_TRUE(at::allclose(w2.matmul(w2.t()), 1e-4 * at::eye(3), 1e-7, 1e-7));
  EXPECT_EQ(parameters["body.layers.0.bias"].abs().sum().item<float>(), 0.0f);
  EXPECT_TRUE(at::equal(policy->log_std(), at::zeros({3})));
  ValueNetwork value(5, NetworkConfig{{64, 64}});
  const at::Tensor v2 = value->named_parameters()["body.layers.2.weight"];
  EXPECT_NEAR(v2.norm().item<float>(), 1.0f, 1e-4);
}

TEST(NetworksTest, GaussianPolicyLogProbEntropyAndSampling) {
  at::manual_seed(1);
  PolicyNetwork policy(ContinuousSpec(), NetworkConfig{{16}});
  const at::Tensor observations = at::randn({4, 5});
  const at::Tensor mean = policy->forward(observations);
  ASSERT_EQ(mean.sizes(), at::IntArrayRef({4, 3}));
  const at::Tensor actions = at::randn({4, 3});
  EXPECT_TRUE(
      at::allclose(policy->LogProb(mean, actions),
                   DiagGaussianLogProb(mean, policy->log_std(), actions)));
  EXPECT_TRUE(at::allclose(policy->Entropy(mean),
                           at::full({4}, 3 * 0.5 * std::log(2 * M_PI * M_E))));
  at::Generator a = at::make_generator<at::CPUGeneratorImpl>(7);
  at::Generator b = at::make_generator<at::CPUGeneratorImpl>(7);
  const at::Tensor first = policy->Act(mean, false, a);
  EXPECT_TRUE(at::equal(first, policy->Act(mean, false, b)));
  EXPECT_FALSE(at::equal(first, mean));
  EXPECT_TRUE(at::equal(policy->Act(mean, true, a), mean));
  // Gradients reach the log-std.
  policy->LogProb(mean, actions).sum().backward();
  EXPECT_TRUE(policy->log_std().grad().defined());
}

TEST(NetworksTest, CategoricalPolicy) {
  EnvSpec spec;
  spec.name = "discrete";
  spec.observation_size = 2;
  spec.discrete = true;
  spec.action_size = 4;
  PolicyNetwork policy(spec, NetworkConfig{{8}});
  EXPECT_FALSE(policy->log_std().defined());
  const at::Tensor logits = policy->forward(at::randn({6, 2}));
  ASSERT_EQ(logits.sizes(), at::IntArrayRef({6, 4}));
  at::Generator g = at::make_generator<at::CPUGeneratorImpl>(3);
  const at::Tensor actions = policy->Act(logits, false, g);
  ASSERT_EQ(actions.sizes(), at::IntArrayRef({6, 1}));
  EXPECT_TRUE(((actions >= 0) & (actions < 4)).all().item<bool>());
  EXPECT_TRUE(at::allclose(policy->LogProb(logits, actions),
                           CategoricalLogProb(logits, actions.reshape({-1}))));
  // The near-zero initial logits make the policy almost uniform.
  EXPECT_NEAR(policy->Entropy(logits).mean().item<float>(), std::log(4.0),
              1e-3);
}

TEST(NetworksTest, ValueNetworkShape) {
  ValueNetwork value(5, NetworkConfig{});
  EXPECT_EQ(value->forward(at::randn({7, 5})).sizes(), at::IntArrayRef({7}));
}

EnvSpec ImageSpec(int64_t channels, int64_t side, int64_t high) {
  EnvSpec spec;
  spec.name = "Image";
  spec.observation_size = channels * side * side;
  spec.observation_shape = {channels, side, side};
  spec.observation_high = high;
  spec.discrete = true;
  spec.action_size = 6;
  return spec;
}

int64_t ParameterCount(torch::nn::Module& module) {
  int64_t count = 0;
  for (const at::Tensor& p : module.parameters()) count += p.numel();
  return count;
}

TEST(TorsoTest, NamesParseAndAutoPicksByTheObservations) {
  for (Torso torso : {Torso::kAuto, Torso::kMlp, Torso::kMinAtar,
                      Torso::kNature, Torso::kEx2Doom}) {
    EXPECT_EQ(ParseTorso(TorsoName(torso)).value(), torso);
  }
  EXPECT_EQ(ParseTorso("resnet").status().message(),
            "unknown torso \"resnet\"; valid: auto, mlp, minatar, nature, "
            "ex2doom");
  EXPECT_EQ(ResolveTorso(Torso::kAuto, ContinuousSpec()).value(), Torso::kMlp);
  EXPECT_EQ(ResolveTorso(Torso::kAuto, ImageSpec(4, 10, 1)).value(),
            Torso::kMinAtar);
  EXPECT_EQ(ResolveTorso(Torso::kAuto, ImageSpec(3, 35, 255)).value(),
            Torso::kMinAtar);
  EXPECT_EQ(ResolveTorso(Torso::kAuto, ImageSpec(3, 36, 255)).value(),
            Torso::kNature);
  EXPECT_EQ(ResolveTorso(Torso::kMlp, ImageSpec(3, 42, 255)).value(),
            Torso::kMlp);
  EXPECT_EQ(
      ResolveTorso(Torso::kNature, ImageSpec(4, 10, 1)).status().message(),
      "torso nature needs frames of at least 36x36 pixels; Image has "
      "4x10x10 (use --torso=minatar)");
  EXPECT_EQ(
      ResolveTorso(Torso::kEx2Doom, ImageSpec(4, 10, 1)).status().message(),
      "torso ex2doom needs frames of at least 16x16 pixels; Image has "
      "4x10x10 (use --torso=minatar)");
  EXPECT_EQ(ResolveTorso(Torso::kEx2Doom, ImageSpec(3, 16, 255)).value(),
            Torso::kEx2Doom);
  EXPECT_EQ(ResolveTorso(Torso::kMinAtar, ContinuousSpec()).status().message(),
            "torso minatar needs image observations; test has vectors of 5 "
            "(use --torso=mlp)");
}

// The published layer sizes, counted: MinAtar's net on Breakout's 4x10x10
// and the DQN net on the maze's 3x42x42 frames.
TEST(TorsoTest, ConvolutionalTorsosHaveThePublishedLayers) {
  at::manual_seed(0);
  PolicyNetwork minatar(ImageSpec(4, 10, 1), NetworkConfig{});
  EXPECT_EQ(ParameterCount(*minatar),
            (4 * 16 * 9 + 16) + (16 * 8 * 8 * 128 + 128) + (128 * 6 + 6));
  ValueNetwork minatar_value(ImageSpec(4, 10, 1), NetworkConfig{});
  EXPECT_EQ(ParameterCount(*minatar_value),
            (4 * 16 * 9 + 16) + (16 * 8 * 8 * 128 + 128) + (128 + 1));
  PolicyNetwork nature(ImageSpec(3, 42, 255), NetworkConfig{});
  EXPECT_EQ(ParameterCount(*nature),
            (3 * 32 * 64 + 32) + (32 * 64 * 16 + 64) + (64 * 64 * 9 + 64) +
                (64 * 1 * 1 * 512 + 512) + (512 * 6 + 6));
  // EX2's first-person-maze policy: 42 -> 10 -> 2 pixels a side.
  PolicyNetwork ex2doom(ImageSpec(3, 42, 255),
                        NetworkConfig{{64, 64}, Torso::kEx2Doom});
  EXPECT_EQ(ParameterCount(*ex2doom), (3 * 16 * 16 + 16) + (16 * 16 * 16 + 16) +
                                          (16 * 2 * 2 * 32 + 32) +
                                          (32 * 6 + 6));
  // Convolutions orthogonal with gain sqrt(2) over their flattened inputs,
  // zero biases; the output layer keeps the policy's 0.01.
  const auto parameters = nature->named_parameters();
  const at::Tensor conv = parameters["conv.layers.0.weight"].reshape({32, -1});
  EXPECT_TRUE(
      at::allclose(conv.matmul(conv.t()), 2.0 * at::eye(32), 1e-4, 1e-4));
  EXPECT_EQ(parameters["conv.layers.0.bias"].abs().sum().item<float>(), 0.0f);
  const at::Tensor out = parameters["body.layers.0.weight"];
  EXPECT_TRUE(at::allclose(out.matmul(out.t()), 1e-4 * at::eye(6), 1e-7, 1e-7));
  // A --hidden for the MLP changes nothing of a convolutional network.
  at::manual_seed(0);
  EXPECT_EQ(
      ParameterCount(*PolicyNetwork(ImageSpec(4, 10, 1), NetworkConfig{{7}})),
      ParameterCount(*minatar));
}

// With a shared torso the value network is the policy's convolutions plus
// its own output layer: both losses reach the same trunk, and the joint
// parameter list holds each tensor once.
TEST(TorsoTest, ASharedTorsoIsOneTrunkForBothNetworks) {
  at::manual_seed(0);
  const EnvSpec spec = ImageSpec(4, 10, 1);
  NetworkConfig config;
  config.shared_torso = true;
  ASSERT_TRUE(CheckNetworkConfig(config, spec).ok());
  PolicyNetwork policy(spec, config);
  ValueNetwork value = MakeValueNetwork(spec, config, *policy);
  const auto trunk = policy->named_parameters();
  const auto value_parameters = value->named_parameters();
  for (const char* name : {"conv.layers.0.weight", "conv.layers.3.weight"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(value_parameters.contains(name));
    EXPECT_TRUE(value_parameters[name].is_same(trunk[name]));
  }
  EXPECT_EQ(value_parameters["body.layers.0.weight"].sizes(),
            at::IntArrayRef({1, 128}));
  const std::vector<at::Tensor> joint = NetworkParameters(*policy, *value);
  // The policy's 6 tensors (2 convolution, 2 dense, 2 output) and the
  // value's output layer.
  EXPECT_EQ(joint.size(), policy->parameters().size() + 2);
  int64_t joint_count = 0;
  for (const at::Tensor& p : joint) joint_count += p.numel();
  EXPECT_EQ(joint_count, ParameterCount(*policy) + 128 + 1);
  // The value loss moves the policy's convolutions.
  const at::Tensor obs =
      at::randint(0, 2, {3, spec.observation_size}, at::kByte);
  value->forward(obs).sum().backward();
  EXPECT_GT(trunk["conv.layers.0.weight"].grad().abs().sum().item<float>(), 0);
  // Separate networks share nothing.
  config.shared_torso = false;
  ValueNetwork own = MakeValueNetwork(spec, config, *policy);
  EXPECT_FALSE(own->named_parameters()["conv.layers.0.weight"].is_same(
      trunk["conv.layers.0.weight"]));
  EXPECT_EQ(NetworkParameters(*policy, *own).size(),
            policy->parameters().size() + own->parameters().size());
  // There is nothing to share in an MLP.
  config.shared_torso = true;
  EXPECT_EQ(CheckNetworkConfig(config, ContinuousSpec()).message(),
            "a shared torso needs a convolutional one, but 'test' gets the "
            "mlp torso (--torso=auto); share with --torso=minatar or nature "
            "on image observations");
}

// Byte observations enter as uint8 and mean value / observation_high: the
// network gives what it gives on the scaled floats.
TEST(TorsoTest, ByteObservationsAreScaledByTheirHigh) {
  for (Torso torso : {Torso::kMlp, Torso::kNature}) {
    at::manual_seed(3);
    const EnvSpec spec = ImageSpec(3, 36, 255);
    PolicyNetwork policy(spec, NetworkConfig{{32}, torso});
    ValueNetwork value(spec, NetworkConfig{{32}, torso});
    const at::Tensor bytes =
        at::randint(0, 256, {5, spec.observation_size}, at::kByte);
    const at::Tensor floats = bytes.to(at::kFloat) / 255.0;
    const at::Tensor logits = policy->forward(bytes);
    ASSERT_EQ(logits.sizes(), at::IntArrayRef({5, 6}));
    EXPECT_TRUE(at::allclose(logits, policy->forward(floats), 1e-6, 1e-6));
    EXPECT_TRUE(at::allclose(value->forward(bytes), value->forward(floats),
                             1e-6, 1e-6));
    // Each sample is its own: a batch of one gives the row.
    EXPECT_TRUE(at::allclose(policy->forward(bytes.slice(0, 2, 3)),
                             logits.slice(0, 2, 3), 1e-6, 1e-6));
  }
  // Byte observations are never normalised; real ones are.
  RunningMeanStd normalizer(3);
  ASSERT_TRUE(normalizer.Update(at::full({1, 3}, 5.0f)).ok());
  EnvSpec bytes = ImageSpec(3, 1, 1);
  const at::Tensor grid = at::ones({1, 3}, at::kByte);
  EXPECT_TRUE(
      at::equal(ObservationsForNetwork(bytes, normalizer, grid, 10), grid));
  EnvSpec reals = bytes;
  reals.observation_high = 0;
  const at::Tensor x = at::full({1, 3}, 5.0f);
  EXPECT_TRUE(at::equal(ObservationsForNetwork(reals, normalizer, x, 10),
                        normalizer.Normalize(x, 10)));
  // What an environment wrote, in the dtype segments hold.
  const double written[] = {0, 1, 1, 255, 0, 7};
  EXPECT_TRUE(
      at::equal(ObservationTensor(ImageSpec(3, 1, 255), written, 2),
                at::tensor({0, 1, 1, 255, 0, 7}, at::kByte).reshape({2, 3})));
  EXPECT_TRUE(
      at::equal(ObservationTensor(reals, written, 2),
                at::tensor({0, 1, 1, 255, 0, 7}, at::kFloat).reshape({2, 3})));
}

// A Dict of a 1x6x6 camera and 3 joint values: the camera through a
// MinAtar torso of its own, the joints as they are, then the MLP; only the
// joints are normalised, the camera enters divided by its high.
TEST(TorsoTest, ADictObservationGetsATorsoPerImageAndNormalisedVectors) {
  EnvSpec spec;
  spec.name = "dict";
  spec.observation_size = 39;
  spec.observation_keys = {{"camera", 36, {1, 6, 6}, 255},
                           {"joints", 3, {}, 0}};
  spec.discrete = true;
  spec.action_size = 4;
  ASSERT_TRUE(CheckNetworkConfig(NetworkConfig{{16}}, spec).ok());
  at::manual_seed(4);
  PolicyNetwork policy(spec, NetworkConfig{{16}});
  ValueNetwork value(spec, NetworkConfig{{16}});
  ASSERT_FALSE(policy->dict_torso().is_empty());
  ASSERT_EQ(policy->dict_torso()->convs().size(), 2u);
  EXPECT_FALSE(policy->dict_torso()->convs()[0].is_empty());
  EXPECT_TRUE(policy->dict_torso()->convs()[1].is_empty());
  // MinAtar's torso gives 128 features; the joints add 3.
  EXPECT_EQ(policy->dict_torso()->features(), 128 + 3);
  const at::Tensor row = at::cat(
      {at::randint(0, 256, {5, 36}).to(at::kFloat), at::randn({5, 3})}, 1);
  EXPECT_EQ(policy->forward(row).sizes(), at::IntArrayRef({5, 4}));
  EXPECT_EQ(value->forward(row).sizes(), at::IntArrayRef({5}));

  RunningMeanStd normalizer(39);
  ASSERT_TRUE(normalizer.Update(at::randn({20, 39}) * 3 + 1).ok());
  const at::Tensor inputs = ObservationsForNetwork(spec, normalizer, row, 10);
  EXPECT_TRUE(at::allclose(inputs.slice(1, 0, 36), row.slice(1, 0, 36) / 255));
  EXPECT_TRUE(at::allclose(inputs.slice(1, 36, 39),
                           normalizer.Normalize(row, 10).slice(1, 36, 39)));

  EXPECT_THAT(
      CheckNetworkConfig(NetworkConfig{{16}, Torso::kNature}, spec).message(),
      ::testing::HasSubstr("--torso=nature does not apply"));
  NetworkConfig recurrent{{16}};
  recurrent.core = Core::kGru;
  recurrent.core_size = 8;
  EXPECT_THAT(CheckNetworkConfig(recurrent, spec).message(),
              ::testing::HasSubstr("which a recurrent --core does not take"));
  spec.observation_keys[0].shape = {9, 2, 2};  // below 3x3
  EXPECT_FALSE(CheckNetworkConfig(NetworkConfig{{16}}, spec).ok());
}

}  // namespace
}  // namespace vantage
