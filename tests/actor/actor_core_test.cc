#include "actor/actor_core.h"

#include <ATen/ATen.h>

#include "common/nn/distributions.h"
#include "common/rollout/segment.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fakes/random_policy.h"

namespace vantage {
namespace {

ActorConfig Config() {
  ActorConfig config;
  config.env = "InvertedPendulum";
  config.num_envs = 3;
  config.segment_length = 40;
  config.seed = 5;
  config.actor_id = 2;
  config.network.hidden = {16};
  return config;
}

// The weights of a learner's freshly initialised policy.
PolicyWeights InitialWeights(const EnvSpec& spec, int64_t version) {
  at::manual_seed(11);
  PolicyNetwork policy(spec, Config().network);
  return ExportPolicyWeights(*policy, RunningMeanStd(spec.observation_size),
                             version);
}

std::unique_ptr<ActorCore> MakeActor() {
  auto actor = std::move(*ActorCore::Create(Config()));
  EXPECT_TRUE(actor->SetWeights(InitialWeights(actor->spec(), 0)).ok());
  return actor;
}

std::vector<Segment> Collect(ActorCore& actor) {
  SegmentQueue queue(16);
  EXPECT_TRUE(actor.CollectSegments(queue).ok());
  queue.Close();
  std::vector<Segment> segments;
  while (true) {
    absl::StatusOr<Segment> s = queue.Receive();
    if (!s.ok()) break;
    segments.push_back(std::move(*s));
  }
  return segments;
}

TEST(ActorCoreTest, SegmentsAreValidAndNumberedPerSlot) {
  auto actor = MakeActor();
  for (int round = 0; round < 2; ++round) {
    const std::vector<Segment> segments = Collect(*actor);
    ASSERT_EQ(segments.size(), 3u);
    for (int64_t i = 0; i < 3; ++i) {
      const Segment& s = segments[i];
      EXPECT_TRUE(ValidateSegment(s, actor->spec(), 40).ok());
      EXPECT_EQ(s.actor_id, 2);
      EXPECT_EQ(s.env_slot, i);
      EXPECT_EQ(s.sequence, round);
      EXPECT_EQ(s.steps(), 40);
      // InvertedPendulum rewards 1 per step; its episodes end quickly.
      EXPECT_TRUE(at::equal(s.rewards, at::ones({40})));
      EXPECT_GT(s.terminated.sum().item<int64_t>(), 0);
      EXPECT_EQ(s.episode_returns.size(),
                static_cast<size_t>(s.terminated.sum().item<int64_t>()));
    }
  }
  EXPECT_EQ(actor->env_steps(), 2 * 3 * 40);
}

// Each segment says which step of its episode its step 0 is: the first
// episode ending in it is that many steps longer than the steps it has
// there, and the next segment goes on from the last end.
TEST(ActorCoreTest, SegmentsSayWhereInItsEpisodeTheyStart) {
  auto actor = MakeActor();
  std::vector<int64_t> expected(3, 0);  // every env starts an episode
  for (int round = 0; round < 4; ++round) {
    const std::vector<Segment> segments = Collect(*actor);
    ASSERT_EQ(segments.size(), 3u);
    for (int64_t i = 0; i < 3; ++i) {
      const Segment& s = segments[i];
      EXPECT_EQ(s.first_episode_step, expected[i]) << round << " " << i;
      int64_t step = s.first_episode_step;
      size_t episode = 0;
      for (int64_t t = 0; t < s.steps(); ++t, ++step) {
        if (!s.terminated[t].item<bool>() && !s.truncated[t].item<bool>()) {
          continue;
        }
        ASSERT_LT(episode, s.episode_lengths.size());
        EXPECT_EQ(s.episode_lengths[episode++], step + 1) << t;
        step = -1;
      }
      expected[i] = step;
    }
  }
}

TEST(ActorCoreTest, BehaviourLogProbsAreThoseOfTheActingWeights) {
  auto actor = MakeActor();
  // Publish weights (version 7) with a shifted normaliser.
  PolicyNetwork reference(actor->spec(), Config().network);
  RunningMeanStd normalizer(4);
  ASSERT_TRUE(normalizer.Update(at::randn({50, 4}) * 0.1 + 0.3).ok());
  const PolicyWeights weights = ExportPolicyWeights(*reference, normalizer, 7);
  ASSERT_TRUE(actor->SetWeights(weights).ok());
  const std::vector<Segment> segments = Collect(*actor);
  for (const Segment& s : segments) {
    EXPECT_EQ(s.policy_version, 7);
    const at::Tensor observations = s.observations.slice(0, 0, 40);
    const at::Tensor output =
        reference->forward(normalizer.Normalize(observations, 10.0));
    EXPECT_TRUE(at::allclose(reference->LogProb(output, s.actions),
                             s.behaviour_log_probs, 1e-5, 1e-5));
  }
}

TEST(ActorCoreTest, MlpPoliciesActWithoutLibTorchConvolutionalOnesWithIt) {
  EXPECT_TRUE(MakeActor()->acts_without_libtorch());
  ActorConfig config = Config();
  config.env = "MinAtarBreakout";
  config.network = NetworkConfig();  // the MinAtar torso
  config.segment_length = 8;
  auto actor = std::move(*ActorCore::Create(config));
  at::manual_seed(11);
  PolicyNetwork policy(actor->spec(), config.network);
  ASSERT_TRUE(
      actor
          ->SetWeights(ExportPolicyWeights(
              *policy, RunningMeanStd(actor->spec().observation_size), 0))
          .ok());
  EXPECT_FALSE(actor->acts_without_libtorch());
  for (const Segment& s : Collect(*actor)) {
    EXPECT_TRUE(ValidateSegment(s, actor->spec(), 8).ok());
  }
}

TEST(ActorCoreTest, SameSeedSameSegments) {
  auto a = MakeActor();
  auto b = MakeActor();
  const std::vector<Segment> first = Collect(*a);
  const std::vector<Segment> second = Collect(*b);
  for (size_t i = 0; i < first.size(); ++i) {
    EXPECT_TRUE(at::equal(first[i].observations, second[i].observations));
    EXPECT_TRUE(at::equal(first[i].actions, second[i].actions));
  }
}

TEST(ActorCoreTest, BadConfigAndWeightsAreRefused) {
  ActorConfig config = Config();
  config.num_envs = 0;
  EXPECT_FALSE(ActorCore::Create(config).ok());
  config = Config();
  config.env = "Nope";
  EXPECT_FALSE(ActorCore::Create(config).ok());
  auto actor = std::move(*ActorCore::Create(Config()));
  SegmentQueue queue(4);
  EXPECT_EQ(actor->CollectSegments(queue).code(),
            absl::StatusCode::kFailedPrecondition);
  PolicyNetwork other(actor->spec(), NetworkConfig{{8, 8}});
  RunningMeanStd normalizer(4);
  EXPECT_FALSE(
      actor->SetWeights(ExportPolicyWeights(*other, normalizer, 1)).ok());
  EXPECT_EQ(actor->policy_version(), 0);
  PolicyWeights nan_weights = InitialWeights(actor->spec(), 3);
  nan_weights.parameters.back().view({-1})[0] = NAN;
  EXPECT_FALSE(actor->SetWeights(nan_weights).ok());
}

// Masked actions over 100k steps of LitButtons (3 of 32 buttons legal)
// from a policy with random weights (logits far apart, so that an unmasked
// sample would often be illegal): every action is legal under the mask its
// segment carries (the environment would refuse it otherwise), and the
// behaviour log-probabilities are the policy's under those masks.
TEST(ActorCoreTest, MaskedActionsAreNeverIllegalOver100kSteps) {
  ActorConfig config = Config();
  config.env = "LitButtons";
  config.num_envs = 8;
  config.segment_length = 64;
  auto actor = std::move(*ActorCore::Create(config));
  ASSERT_TRUE(actor->spec().action_masks);
  at::manual_seed(12);
  PolicyNetwork policy(actor->spec(), config.network);
  RunningMeanStd normalizer(actor->spec().observation_size);
  RandomisePolicy(*policy, normalizer, actor->spec());
  {
    at::NoGradGuard no_grad;
    for (at::Tensor& parameter : policy->parameters()) parameter.mul_(3.0);
  }
  ASSERT_TRUE(
      actor->SetWeights(ExportPolicyWeights(*policy, normalizer, 1)).ok());
  ASSERT_TRUE(actor->acts_without_libtorch());
  int64_t steps = 0;
  int64_t unmasked_would_be_illegal = 0;
  while (steps < 100000) {
    for (const Segment& s : Collect(*actor)) {
      ASSERT_TRUE(ValidateSegment(s, actor->spec(), 64).ok())
          << ValidateSegment(s, actor->spec(), 64);
      const at::Tensor actions = s.actions.to(at::kLong);
      EXPECT_TRUE(s.action_masks.gather(1, actions).all().item<bool>());
      steps += s.steps();
      if (steps > 64 * 8) continue;  // the log-probabilities once
      at::NoGradGuard no_grad;
      const at::Tensor output = policy->forward(
          normalizer.Normalize(s.observations.slice(0, 0, 64), 10.0));
      EXPECT_TRUE(at::allclose(
          policy->LogProb(MaskLogits(output, s.action_masks), s.actions),
          s.behaviour_log_probs, 1e-5, 1e-5));
      unmasked_would_be_illegal +=
          s.action_masks.gather(1, output.argmax(1, true))
              .logical_not()
              .sum()
              .item<int64_t>();
    }
  }
  EXPECT_EQ(actor->env_steps(), steps);
  // The policy alone prefers illegal buttons most of the time.
  EXPECT_GT(unmasked_would_be_illegal, 64 * 8 / 2);
}

}  // namespace
}  // namespace vantage
