#include "learner/learner_core.h"

#include <ATen/ATen.h>
#include <torch/serialize/archive.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/algorithms/trpo/trpo_config.h"
#include "learner/checkpoint/checkpoint.h"
#include "learner/exploration/ex2_bonus.h"
#include "tests/fakes/learner_batches.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

bool AllFinite(const PolicyWeights& weights) {
  for (const at::Tensor& p : weights.parameters) {
    if (!at::isfinite(p).all().item<bool>()) return false;
  }
  return true;
}

// A learner whose value gate lets everything finite through, so that a
// poisoned batch reaches the update and only the rollback stands between it
// and the weights.
LearnerConfig UngatedConfig(const EnvSpec& spec, const std::string& algorithm) {
  LearnerConfig config = TestLearnerConfig(spec, algorithm);
  config.scale_rewards = false;
  config.value_limits.max_abs_reward = kInfinity;
  config.value_limits.max_abs_log_prob = kInfinity;
  return config;
}

class RollbackTest : public ::testing::TestWithParam<std::string> {};

TEST_P(RollbackTest, APoisonedBatchIsUndoneAndTheRunGoesOn) {
  auto actor = MakeTestActor(GetParam() == "a2c" ? 60 : kTestHorizon);
  const LearnerConfig config = UngatedConfig(actor->spec(), GetParam());
  auto learner = *LearnerCore::Create(config);
  UpdateWith(*learner, ActOneBatch(*actor, *learner));
  std::vector<Segment> poisoned = ActOneBatch(*actor, *learner);
  for (Segment& segment : poisoned) {
    segment.rewards.fill_(3e38f);
    segment.behaviour_log_probs.fill_(-3e38f);
  }
  const PolicyWeights before = learner->CurrentWeights();

  const UpdateStats stats = UpdateWith(*learner, poisoned);
  EXPECT_TRUE(stats.rolled_back);
  EXPECT_THAT(stats.rollback_reason, HasSubstr("non-finite"));
  EXPECT_EQ(stats.rolled_back_updates, 1);
  // The version advances (synchronous actors wait for it) with the weights
  // and normaliser of before.
  const PolicyWeights after = learner->CurrentWeights();
  EXPECT_EQ(after.version, before.version + 1);
  ASSERT_EQ(after.parameters.size(), before.parameters.size());
  for (size_t i = 0; i < before.parameters.size(); ++i) {
    EXPECT_TRUE(after.parameters[i].equal(before.parameters[i])) << i;
  }
  EXPECT_EQ(after.normalizer_count, before.normalizer_count);
  EXPECT_TRUE(after.normalizer_mean.equal(before.normalizer_mean));
  EXPECT_TRUE(AllFinite(after));

  // An honest batch trains again, from intact optimiser state.
  const UpdateStats next = UpdateWith(*learner, ActOneBatch(*actor, *learner));
  EXPECT_FALSE(next.rolled_back) << next.rollback_reason;
  EXPECT_EQ(next.rolled_back_updates, 1);
  const PolicyWeights trained = learner->CurrentWeights();
  EXPECT_TRUE(AllFinite(trained));
  EXPECT_FALSE(trained.parameters[0].equal(before.parameters[0]));

  // The count survives a checkpoint.
  const std::string path =
      std::string(::testing::TempDir()) + "/rollback_" + GetParam() + ".pt";
  ASSERT_TRUE(WriteCheckpoint(path, *learner, {}).ok());
  absl::StatusOr<std::unique_ptr<LearnerCore>> restored =
      ReadCheckpoint(path, config);
  ASSERT_TRUE(restored.ok()) << restored.status();
  const UpdateStats resumed =
      UpdateWith(**restored, ActOneBatch(*actor, **restored));
  EXPECT_EQ(resumed.rolled_back_updates, 1);
}

INSTANTIATE_TEST_SUITE_P(Algorithms, RollbackTest,
                         ::testing::Values("ppo", "a2c", "trpo"));

TEST(RollbackLimitTest, AGradientNormExplosionIsUndone) {
  for (const std::string algorithm : {"ppo", "a2c"}) {
    SCOPED_TRACE(algorithm);
    auto actor = MakeTestActor(algorithm == "a2c" ? 60 : kTestHorizon);
    LearnerConfig config = TestLearnerConfig(actor->spec(), algorithm);
    // Any real gradient is larger than this.
    config.rollback_gradient_norm = 1e-12;
    auto learner = *LearnerCore::Create(config);
    const PolicyWeights before = learner->CurrentWeights();
    const UpdateStats stats =
        UpdateWith(*learner, ActOneBatch(*actor, *learner));
    EXPECT_TRUE(stats.rolled_back);
    EXPECT_THAT(stats.rollback_reason, HasSubstr("gradient norm"));
    EXPECT_GT(stats.algorithm.max_gradient_norm, 0.0);
    EXPECT_TRUE(
        learner->CurrentWeights().parameters[0].equal(before.parameters[0]));
  }
}

// An update rolled back undoes the EX2 model's fit on its batch and keeps
// the batch out of the pool; the next honest batch fits from there.
TEST(RollbackTest, AnEx2FitOnAPoisonedBatchIsUndoneToo) {
  auto actor = MakeTestActor();
  LearnerConfig config = UngatedConfig(actor->spec(), "trpo");
  Ex2Config ex2;
  ex2.replay_min = 1;
  ex2.first_train_iterations = 20;
  ex2.train_iterations = 10;
  config.exploration.ex2 = ex2;
  auto learner = *LearnerCore::Create(config);
  // The first batch only fills the pool; the second fits.
  for (int i = 0; i < 2; ++i) {
    const UpdateStats honest =
        UpdateWith(*learner, ActOneBatch(*actor, *learner));
    EXPECT_FALSE(honest.rolled_back) << honest.rollback_reason;
  }
  const auto model_parameters = [&] {
    std::vector<at::Tensor> copies;
    for (const at::Tensor& p : learner->exploration()->parameters()) {
      copies.push_back(p.detach().clone());
    }
    return copies;
  };
  const std::vector<at::Tensor> before = model_parameters();
  const int64_t pooled = learner->exploration()->pool().total_added();
  EXPECT_EQ(pooled, 2 * kTestEnvs * kTestHorizon);
  std::vector<Segment> poisoned = ActOneBatch(*actor, *learner);
  for (Segment& segment : poisoned) segment.rewards.fill_(3e38f);
  const UpdateStats stats = UpdateWith(*learner, poisoned);
  EXPECT_TRUE(stats.rolled_back);
  EXPECT_EQ(stats.exploration.fit_steps, 10);  // it did fit, then was undone
  const std::vector<at::Tensor> after = model_parameters();
  for (size_t i = 0; i < before.size(); ++i) {
    EXPECT_TRUE(after[i].equal(before[i])) << i;
  }
  EXPECT_EQ(learner->exploration()->pool().total_added(), pooled);
  const UpdateStats next = UpdateWith(*learner, ActOneBatch(*actor, *learner));
  EXPECT_FALSE(next.rolled_back) << next.rollback_reason;
  EXPECT_EQ(learner->exploration()->pool().total_added(),
            pooled + kTestEnvs * kTestHorizon);
}

// An EX2 model whose weights make its bonus non-finite (a checkpoint with a
// huge but finite weight, found by the entries fuzzer) undoes the update
// instead of failing it, even with reward scaling, which would refuse the
// non-finite rewards.
TEST(RollbackTest, AnEx2ModelThatDivergesIsUndone) {
  auto actor = MakeTestActor();
  LearnerConfig config = UngatedConfig(actor->spec(), "trpo");
  config.scale_rewards = true;
  Ex2Config ex2;
  ex2.replay_min = 1;
  ex2.first_train_iterations = 5;
  ex2.train_iterations = 5;
  config.exploration.ex2 = ex2;
  auto learner = *LearnerCore::Create(config);
  for (int i = 0; i < 2; ++i) {
    UpdateWith(*learner, ActOneBatch(*actor, *learner));
  }
  torch::serialize::OutputArchive out;
  learner->Save(out);
  at::Tensor weight;
  {
    std::ostringstream bytes;
    out.save_to(bytes);
    torch::serialize::InputArchive in;
    std::istringstream stream(bytes.str());
    in.load_from(stream);
    in.read("ex2.model.exemplar_encoder.mean.layers.1.weight", weight);
  }
  weight = weight.clone();
  weight.view(-1)[0] = 2e29f;
  out.write("ex2.model.exemplar_encoder.mean.layers.1.weight", weight);
  std::ostringstream bytes;
  out.save_to(bytes);
  torch::serialize::InputArchive in;
  std::istringstream stream(bytes.str());
  in.load_from(stream);
  absl::StatusOr<std::unique_ptr<LearnerCore>> loaded =
      LearnerCore::Load(config, in);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  const int64_t pooled = (*loaded)->exploration()->pool().total_added();
  const UpdateStats stats = UpdateWith(**loaded, ActOneBatch(*actor, **loaded));
  EXPECT_TRUE(stats.rolled_back);
  EXPECT_THAT(stats.rollback_reason, HasSubstr("non-finite exploration bonus"));
  EXPECT_EQ((*loaded)->exploration()->pool().total_added(), pooled);
  EXPECT_TRUE(AllFinite((*loaded)->CurrentWeights()));
}

TEST(RollbackLimitTest, AnHonestRunNeverRollsBack) {
  auto actor = MakeTestActor();
  auto learner = *LearnerCore::Create(TestLearnerConfig(actor->spec(), "ppo"));
  for (int i = 0; i < 3; ++i) {
    const UpdateStats stats =
        UpdateWith(*learner, ActOneBatch(*actor, *learner));
    EXPECT_FALSE(stats.rolled_back) << stats.rollback_reason;
    EXPECT_TRUE(std::isfinite(stats.algorithm.max_gradient_norm));
  }
}

TEST(BufferBudgetTest, StreamsThatNeverCompleteCannotGrowTheBuffers) {
  auto actor = MakeTestActor(/*segment_length=*/kTestHorizon / 2);
  LearnerConfig config = TestLearnerConfig(actor->spec(), "ppo");
  config.max_buffered_steps = 3 * kTestHorizon;
  auto learner = *LearnerCore::Create(config);
  // Half-rollouts of 20 streams nobody completes, then an honest batch.
  const std::vector<Segment> first = ActOneBatch(*actor, *learner);
  std::vector<Segment> queue;
  for (int64_t stream = 0; stream < 20; ++stream) {
    Segment orphan = first[0];
    orphan.actor_id = 100 + stream;
    queue.push_back(orphan);
  }
  for (const Segment& s : first) queue.push_back(s);
  for (const Segment& s : ActOneBatch(*actor, *learner)) queue.push_back(s);
  const UpdateStats stats = UpdateWith(*learner, queue);
  EXPECT_EQ(stats.policy_version, 1);
  EXPECT_LE(learner->stitcher().buffered_steps(), 3 * kTestHorizon);
  EXPECT_GE(stats.evicted_steps, 20 * kTestHorizon / 2 - 3 * kTestHorizon);
  EXPECT_EQ(stats.evicted_steps, learner->stitcher().stats().evicted_steps);
}

// Checkpoints `learner` as `name`, restores it under `config`, and expects
// both to give the same weights after one more batch. Returns the path.
std::string ExpectACheckpointContinuesExactly(ActorCore& actor,
                                              LearnerCore& learner,
                                              const LearnerConfig& config,
                                              const std::string& name) {
  const std::string path =
      std::string(::testing::TempDir()) + "/" + name + ".pt";
  EXPECT_TRUE(WriteCheckpoint(path, learner, {}).ok());
  absl::StatusOr<std::unique_ptr<LearnerCore>> restored =
      ReadCheckpoint(path, config);
  EXPECT_TRUE(restored.ok()) << restored.status();
  if (!restored.ok()) return path;
  const std::vector<Segment> next = ActOneBatch(actor, learner);
  UpdateWith(learner, next);
  UpdateWith(**restored, next);
  ExpectSameWeights(learner, **restored);
  return path;
}

// Pixel-style observations stay uint8 from the environment to the
// learner's batches, are never normalised, and train a convolutional
// network; a checkpoint continues it exactly.
TEST(ByteObservationsTest, TravelAsBytesAndTrainAConvolutionalNetwork) {
  for (const std::string env : {"MinAtarBreakout", "FirstPersonMaze"}) {
    SCOPED_TRACE(env);
    auto actor = MakeTestActor(60, env);
    ASSERT_TRUE(actor->spec().byte_observations());
    LearnerConfig config = TestLearnerConfig(actor->spec(), "a2c");
    auto learner = *LearnerCore::Create(config);
    const PolicyWeights initial = learner->CurrentWeights();
    // The convolutions come first.
    EXPECT_EQ(initial.parameters[0].dim(), 4);
    const std::vector<Segment> batch = ActOneBatch(*actor, *learner);
    for (const Segment& segment : batch) {
      EXPECT_EQ(segment.observations.scalar_type(), at::kByte);
      EXPECT_EQ(segment.final_observations.scalar_type(), at::kByte);
      EXPECT_GT(segment.observations.max().item<int>(), 0);
    }
    const UpdateStats stats = UpdateWith(*learner, batch);
    EXPECT_FALSE(stats.rolled_back) << stats.rollback_reason;
    const PolicyWeights trained = learner->CurrentWeights();
    EXPECT_FALSE(trained.parameters[0].equal(initial.parameters[0]));
    EXPECT_EQ(trained.normalizer_count, initial.normalizer_count);
    EXPECT_TRUE(trained.normalizer_mean.equal(initial.normalizer_mean));

    ExpectACheckpointContinuesExactly(*actor, *learner, config, "bytes_" + env);
  }
  // A torso that cannot take the observations is refused up front.
  auto actor = MakeTestActor(60, "MinAtarBreakout");
  LearnerConfig config = TestLearnerConfig(actor->spec(), "a2c");
  config.network.torso = Torso::kNature;
  EXPECT_THAT(LearnerCore::Create(config).status().message(),
              HasSubstr("torso nature needs frames of at least 36x36"));
  // TRPO's linear baseline fits observation values, not pixels.
  LearnerConfig linear = TestLearnerConfig(actor->spec(), "trpo");
  linear.algorithm.Mutable<TrpoConfig>().linear_baseline = true;
  EXPECT_THAT(LearnerCore::Create(linear).status().message(),
              HasSubstr("--trpo_linear_baseline fits the observations' "
                        "values and squares; MinAtarBreakout's observations "
                        "are images (bytes): use the value network"));
}

// PPO and A2C train one trunk under both losses; a checkpoint keeps it one
// (a restored learner continues exactly) and says so, and the algorithm
// that fits its value network alone is refused.
// --normalize_observations=false: the normaliser keeps its initial
// statistics through updates and checkpoints (the actors then pass the
// environment's values through, see RunningMeanStdTest), while the
// networks train; by default it follows the observations.
TEST(ObservationNormalisationTest, ARunThatNormalisesNoneKeepsTheIdentity) {
  for (const bool normalise : {false, true}) {
    SCOPED_TRACE(normalise);
    auto actor = MakeTestActor(kTestHorizon);
    LearnerConfig config = TestLearnerConfig(actor->spec(), "ppo");
    config.normalize_observations = normalise;
    auto learner = *LearnerCore::Create(config);
    const PolicyWeights initial = learner->CurrentWeights();
    const UpdateStats stats =
        UpdateWith(*learner, ActOneBatch(*actor, *learner));
    EXPECT_FALSE(stats.rolled_back) << stats.rollback_reason;
    const PolicyWeights trained = learner->CurrentWeights();
    EXPECT_FALSE(trained.parameters[0].equal(initial.parameters[0]));
    EXPECT_EQ(trained.normalizer_count == initial.normalizer_count, !normalise);
    EXPECT_EQ(trained.normalizer_mean.equal(initial.normalizer_mean),
              !normalise);
    EXPECT_EQ(trained.normalizer_var.equal(initial.normalizer_var), !normalise);
    if (!normalise) {
      ExpectACheckpointContinuesExactly(*actor, *learner, config,
                                        "unnormalised");
      EXPECT_TRUE(learner->CurrentWeights().normalizer_mean.equal(
          initial.normalizer_mean));
    }
  }
}

// `segments` (which end no episode) with one step of each cut off by a
// time limit (its final observation the state after it), or, if
// `as_terminal`, ended there; the episode is reported as the actor would.
std::vector<Segment> WithAnEndAtStep(std::vector<Segment> segments,
                                     int64_t step, bool as_terminal) {
  for (Segment& s : segments) {
    EXPECT_FALSE(s.terminated.any().item<bool>() ||
                 s.truncated.any().item<bool>());
    s.terminated = s.terminated.clone();
    s.truncated = s.truncated.clone();
    s.episode_lengths = {s.first_episode_step + step + 1};
    s.episode_returns = {s.rewards.slice(0, 0, step + 1).sum().item<double>()};
    if (as_terminal) {
      s.terminated[step] = true;
    } else {
      s.truncated[step] = true;
      s.final_observations = s.observations.slice(0, step + 1, step + 2);
    }
  }
  return segments;
}

double LargestDifference(LearnerCore& a, LearnerCore& b) {
  const PolicyWeights wa = a.CurrentWeights();
  const PolicyWeights wb = b.CurrentWeights();
  double largest = 0.0;
  for (size_t i = 0; i < wa.parameters.size(); ++i) {
    largest = std::max(
        largest,
        (wa.parameters[i] - wb.parameters[i]).abs().max().item<double>());
  }
  return largest;
}

// --bootstrap_time_limits=false: a learner trains on a time limit as on a
// terminal step (to rounding), the critic's fit (the linear baseline's, which
// the next update's advantages read) included; bootstrapped, it trains
// otherwise.
TEST(TimeLimitTest, AReturnEndedAtTheLimitTrainsAsATerminalStep) {
  for (const std::string algorithm : {"ppo", "trpo"}) {
    SCOPED_TRACE(algorithm);
    // HalfCheetah never terminates, so the one end is the test's.
    auto actor = MakeTestActor(kTestHorizon, "HalfCheetah");
    LearnerConfig bootstrapped = TestLearnerConfig(actor->spec(), algorithm);
    if (algorithm == "trpo") {
      bootstrapped.algorithm.Mutable<TrpoConfig>().linear_baseline = true;
    }
    LearnerConfig ended = bootstrapped;
    ended.bootstrap_time_limits = false;
    auto learner = *LearnerCore::Create(ended);
    auto terminal = *LearnerCore::Create(bootstrapped);
    auto bootstrapping = *LearnerCore::Create(bootstrapped);
    // Three updates: the linear baseline starts at 0, so its first fit is
    // the same either way; the second fit, on ended targets, is what the
    // third update's advantages read.
    for (int update = 0; update < 3; ++update) {
      const std::vector<Segment> batch = ActOneBatch(*actor, *learner);
      const UpdateStats stats =
          UpdateWith(*learner, WithAnEndAtStep(batch, 5, false));
      EXPECT_FALSE(stats.rolled_back) << stats.rollback_reason;
      UpdateWith(*terminal, WithAnEndAtStep(batch, 5, true));
      UpdateWith(*bootstrapping, WithAnEndAtStep(batch, 5, false));
    }
    // The critic values the truncated steps' final observations in the same
    // pass as the others, a pass of other rows that rounds differently in
    // the last bits (how much depends on the BLAS kernels; a near-tie in a
    // max or a clip could amplify it); a bootstrapped limit changes the
    // weights far more.
    EXPECT_LT(LargestDifference(*learner, *terminal), 1e-6);
    EXPECT_GT(LargestDifference(*learner, *bootstrapping), 1e-4);
  }
}

// --trpo_zero_baseline: no critic, every state valued 0, so an advantage
// is a sum of discounted rewards. The linear baseline starts at exactly 0,
// so the first updates agree; the value network's first values are not 0,
// and after its first fit neither are the linear baseline's.
TEST(ZeroBaselineTest, EveryStateIsValuedZero) {
  auto actor = MakeTestActor(kTestHorizon, "HalfCheetah");
  LearnerConfig zero_config = TestLearnerConfig(actor->spec(), "trpo");
  LearnerConfig linear_config = zero_config;
  const LearnerConfig value_config = zero_config;
  zero_config.algorithm.Mutable<TrpoConfig>().zero_baseline = true;
  linear_config.algorithm.Mutable<TrpoConfig>().linear_baseline = true;
  auto zero = *LearnerCore::Create(zero_config);
  auto linear = *LearnerCore::Create(linear_config);
  auto valued = *LearnerCore::Create(value_config);
  for (int update = 0; update < 2; ++update) {
    const std::vector<Segment> batch = ActOneBatch(*actor, *zero);
    const UpdateStats stats = UpdateWith(*zero, batch);
    EXPECT_FALSE(stats.rolled_back) << stats.rollback_reason;
    EXPECT_EQ(stats.algorithm.value_loss, 0.0);
    UpdateWith(*linear, batch);
    UpdateWith(*valued, batch);
    if (update == 0) {
      EXPECT_LT(LargestDifference(*zero, *linear), 1e-6);
      EXPECT_GT(LargestDifference(*zero, *valued), 1e-4);
    }
  }
  EXPECT_GT(LargestDifference(*zero, *linear), 1e-4);
  ExpectACheckpointContinuesExactly(*actor, *zero, zero_config, "zero");

  // Unlike the linear baseline it takes frames; and it is one critic.
  auto frames = MakeTestActor(kTestHorizon, "MinAtarBreakout");
  LearnerConfig on_frames = TestLearnerConfig(frames->spec(), "trpo");
  on_frames.algorithm.Mutable<TrpoConfig>().zero_baseline = true;
  auto learner = *LearnerCore::Create(on_frames);
  const UpdateStats stats =
      UpdateWith(*learner, ActOneBatch(*frames, *learner));
  EXPECT_FALSE(stats.rolled_back) << stats.rollback_reason;
  zero_config.algorithm.Mutable<TrpoConfig>().linear_baseline = true;
  EXPECT_EQ(LearnerCore::Create(zero_config).status().message(),
            "trpo.linear_baseline and trpo.zero_baseline are two different "
            "critics; set one of them");
}

// EX2's convolutional model on frames: it fits and shapes the rewards of
// MinAtar's images, and a checkpoint continues it exactly; on vector
// observations it is refused up front.
TEST(Ex2ConvTest, FitsOnFramesAndResumesExactly) {
  auto actor = MakeTestActor(kTestHorizon, "MinAtarBreakout");
  LearnerConfig config = TestLearnerConfig(actor->spec(), "trpo");
  Ex2Config ex2;
  ex2.encoder = "conv";
  ex2.replay_min = 1;
  ex2.first_train_iterations = 20;
  ex2.train_iterations = 10;
  config.exploration.ex2 = ex2;
  auto learner = *LearnerCore::Create(config);
  const at::Tensor initial =
      learner->exploration()->parameters()[0].detach().clone();
  EXPECT_EQ(initial.dim(), 4);  // the first convolution's filters
  for (int update = 0; update < 2; ++update) {
    const UpdateStats stats =
        UpdateWith(*learner, ActOneBatch(*actor, *learner));
    EXPECT_FALSE(stats.rolled_back) << stats.rollback_reason;
    EXPECT_GT(stats.exploration.bonus_std, 0.0);
    EXPECT_EQ(stats.exploration.fit_steps, update == 0 ? 0 : 20);
  }
  EXPECT_FALSE(learner->exploration()->parameters()[0].equal(initial));
  ExpectACheckpointContinuesExactly(*actor, *learner, config, "ex2_conv");

  auto vectors = MakeTestActor();
  LearnerConfig refused = TestLearnerConfig(vectors->spec(), "trpo");
  refused.exploration.ex2 = ex2;
  EXPECT_THAT(LearnerCore::Create(refused).status().message(),
              HasSubstr("--ex2_encoder=conv convolves an image observation; "));
}

TEST(SharedTorsoTest, OneTrunkTrainsAndResumesAsOne) {
  for (const std::string algorithm : {"a2c", "ppo"}) {
    SCOPED_TRACE(algorithm);
    LearnerConfig config = TestLearnerConfig(
        MakeTestActor(1, "MinAtarBreakout")->spec(), algorithm);
    config.network.shared_torso = true;
    // One segment per stream and batch.
    auto actor = MakeTestActor(config.horizon, "MinAtarBreakout");
    auto learner = *LearnerCore::Create(config);
    const PolicyWeights initial = learner->CurrentWeights();
    const UpdateStats stats =
        UpdateWith(*learner, ActOneBatch(*actor, *learner));
    EXPECT_FALSE(stats.rolled_back) << stats.rollback_reason;
    EXPECT_TRUE(std::isfinite(stats.algorithm.value_loss));
    EXPECT_FALSE(
        learner->CurrentWeights().parameters[0].equal(initial.parameters[0]));

    const std::string path = ExpectACheckpointContinuesExactly(
        *actor, *learner, config, "shared_torso_" + algorithm);

    LearnerConfig separate = config;
    separate.network.shared_torso = false;
    EXPECT_THAT(ReadCheckpoint(path, separate).status().message(),
                HasSubstr("checkpoint's networks share their torso, but the "
                          "run config says the opposite"));
  }
  LearnerConfig config =
      TestLearnerConfig(MakeTestActor(1, "MinAtarBreakout")->spec(), "trpo");
  config.network.shared_torso = true;
  EXPECT_THAT(config.Validate().message(),
              HasSubstr("trpo fits its value network alone"));
  // Vectors have nothing to share.
  auto vectors = MakeTestActor();
  config = TestLearnerConfig(vectors->spec(), "ppo");
  config.network.shared_torso = true;
  EXPECT_THAT(config.Validate().message(),
              HasSubstr("a shared torso needs a convolutional one"));
}

TEST(LearnerConfigTest, RefusesBadLimits) {
  auto actor = MakeTestActor();
  LearnerConfig config = TestLearnerConfig(actor->spec(), "ppo");
  config.rollback_gradient_norm = 0;
  EXPECT_THAT(config.Validate().message(),
              HasSubstr("rollback_gradient_norm must be > 0"));
  config = TestLearnerConfig(actor->spec(), "ppo");
  config.value_limits.max_abs_observation = -1;
  EXPECT_THAT(config.Validate().message(),
              HasSubstr("max_abs_observation must be > 0"));
  config = TestLearnerConfig(actor->spec(), "ppo");
  config.max_buffered_steps = -1;
  EXPECT_THAT(config.Validate().message(),
              HasSubstr("max_buffered_steps must be >= 0"));
}

// An algorithm whose minibatches are slices of a rollout (A2C's) says so
// through its run defaults; the learner holds the horizon to them.
TEST(LearnerConfigTest, A2csHorizonIsWholeMinibatches) {
  auto actor = MakeTestActor();
  LearnerConfig config = TestLearnerConfig(actor->spec(), "a2c");
  config.horizon = 12;
  EXPECT_EQ(config.Validate().message(),
            "a2c needs a horizon that is a multiple of its 5-step "
            "minibatches; got 12");
  config.horizon = 15;
  EXPECT_TRUE(config.Validate().ok()) << config.Validate();
}

}  // namespace
}  // namespace vantage
