#include "learner/checkpoint.h"

#include <ATen/ATen.h>

#include <filesystem>
#include <fstream>

#include "actor/actor_core.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

constexpr int64_t kHorizon = 64;
constexpr int kEnvs = 2;

std::string TempFile(const std::string& name) {
  return std::string(::testing::TempDir()) + "/" + name;
}

LearnerConfig Config(const EnvSpec& spec, const std::string& algorithm) {
  LearnerConfig config;
  config.spec = spec;
  // A2C's rollouts are 5n steps.
  config.horizon = algorithm == "a2c" ? 60 : kHorizon;
  config.rollouts_per_batch = kEnvs;
  config.max_segment_steps = kHorizon;
  config.total_env_steps = 10 * kHorizon * kEnvs;
  config.seed = 3;
  config.scale_rewards = true;
  config.advantage.statistic = *ParseStatistic("maxabs");
  config.advantage.rho = 0.5;
  config.algorithm.name = algorithm;
  config.algorithm.ppo.minibatches = 4;
  config.algorithm.ppo.epochs = 2;
  return config;
}

std::unique_ptr<ActorCore> MakeActor(int64_t segment_length = kHorizon) {
  ActorConfig config;
  config.env = "Hopper";
  config.num_envs = kEnvs;
  config.segment_length = segment_length;
  config.seed = 9;
  return *ActorCore::Create(config);
}

// One batch of segments acted by `learner`'s current weights.
std::vector<Segment> Act(ActorCore& actor, LearnerCore& learner) {
  EXPECT_TRUE(actor.SetWeights(learner.CurrentWeights()).ok());
  SegmentQueue queue(kEnvs);
  EXPECT_TRUE(actor.CollectSegments(queue).ok());
  queue.Close();
  std::vector<Segment> segments;
  for (absl::StatusOr<Segment> s = queue.Receive(); s.ok();
       s = queue.Receive()) {
    segments.push_back(*std::move(s));
  }
  return segments;
}

UpdateStats Update(LearnerCore& learner, const std::vector<Segment>& batch) {
  SegmentQueue queue(batch.size());
  for (const Segment& s : batch) EXPECT_TRUE(queue.Send(s).ok());
  absl::StatusOr<UpdateStats> stats = learner.RunUpdate(queue);
  EXPECT_TRUE(stats.ok()) << stats.status();
  return *stats;
}

void ExpectSameWeights(LearnerCore& a, LearnerCore& b) {
  const PolicyWeights wa = a.CurrentWeights();
  const PolicyWeights wb = b.CurrentWeights();
  EXPECT_EQ(wa.version, wb.version);
  ASSERT_EQ(wa.parameters.size(), wb.parameters.size());
  for (size_t i = 0; i < wa.parameters.size(); ++i) {
    EXPECT_TRUE(wa.parameters[i].equal(wb.parameters[i])) << "parameter " << i;
  }
  EXPECT_EQ(wa.normalizer_count, wb.normalizer_count);
  EXPECT_TRUE(wa.normalizer_mean.equal(wb.normalizer_mean));
  EXPECT_TRUE(wa.normalizer_var.equal(wb.normalizer_var));
}

class CheckpointTest : public ::testing::TestWithParam<std::string> {};

// A learner read back from a checkpoint is the learner that wrote it: same
// weights, normaliser, version and counters now, and, given the same
// segments, the same next update (which needs the optimiser's moments, the
// reward scaler and the minibatch generator to have come back too).
TEST_P(CheckpointTest, RoundTripRestoresTheWholeLearner) {
  auto actor = MakeActor(GetParam() == "a2c" ? 60 : kHorizon);
  const LearnerConfig config = Config(actor->spec(), GetParam());
  auto learner = *LearnerCore::Create(config);
  for (int i = 0; i < 2; ++i) Update(*learner, Act(*actor, *learner));
  const std::string path = TempFile("round_trip_" + GetParam() + ".pt");
  const CheckpointExtras extras = {{"config", "{\"env\": \"Hopper\"}"},
                                   {"blob", std::string("a\0b\xff", 4)}};
  ASSERT_TRUE(WriteCheckpoint(path, *learner, extras).ok());
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));

  absl::StatusOr<std::unique_ptr<LearnerCore>> restored =
      ReadCheckpoint(path, config);
  ASSERT_TRUE(restored.ok()) << restored.status();
  ExpectSameWeights(*learner, **restored);
  EXPECT_EQ((*restored)->env_steps(), learner->env_steps());
  EXPECT_EQ((*restored)->recent_returns(), learner->recent_returns());
  absl::StatusOr<CheckpointExtras> read = ReadCheckpointExtras(path);
  ASSERT_TRUE(read.ok()) << read.status();
  EXPECT_EQ(*read, extras);

  const std::vector<Segment> next = Act(*actor, *learner);
  const UpdateStats a = Update(*learner, next);
  const UpdateStats b = Update(**restored, next);
  EXPECT_EQ(a.algorithm.policy_loss, b.algorithm.policy_loss);
  EXPECT_EQ(a.algorithm.value_loss, b.algorithm.value_loss);
  EXPECT_EQ(a.biased_fraction, b.biased_fraction);
  EXPECT_EQ(a.episodes, b.episodes);
  ExpectSameWeights(*learner, **restored);
}

INSTANTIATE_TEST_SUITE_P(Algorithms, CheckpointTest,
                         ::testing::Values("ppo", "a2c", "trpo"));

class CheckpointErrorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    actor_ = MakeActor();
    config_ = Config(actor_->spec(), "ppo");
    learner_ = *LearnerCore::Create(config_);
    path_ = TempFile("errors.pt");
    ASSERT_TRUE(WriteCheckpoint(path_, *learner_, {}).ok());
  }
  std::unique_ptr<ActorCore> actor_;
  LearnerConfig config_;
  std::unique_ptr<LearnerCore> learner_;
  std::string path_;
};

TEST_F(CheckpointErrorTest, MissingFileIsNotFound) {
  EXPECT_EQ(ReadCheckpoint(TempFile("nothing.pt"), config_).status().code(),
            absl::StatusCode::kNotFound);
}

TEST_F(CheckpointErrorTest, GarbageIsRefusedWithItsPath) {
  const std::string garbage = TempFile("garbage.pt");
  std::ofstream(garbage) << "definitely not a zip archive";
  const absl::Status status = ReadCheckpoint(garbage, config_).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr(garbage));
}

TEST_F(CheckpointErrorTest, AnotherEnvironmentIsRefused) {
  LearnerConfig other = config_;
  other.spec.name = "Walker2d";
  other.spec.observation_size = 17;
  other.spec.action_size = 6;
  const absl::Status status = ReadCheckpoint(path_, other).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("'Hopper'"));
}

TEST_F(CheckpointErrorTest, OtherNetworkSizesAreRefused) {
  LearnerConfig other = config_;
  other.network.hidden = {32, 32};
  const absl::Status status = ReadCheckpoint(path_, other).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("networks"));
}

TEST_F(CheckpointErrorTest, AnotherAlgorithmIsRefused) {
  LearnerConfig other = config_;
  other.algorithm.name = "trpo";
  const absl::Status status = ReadCheckpoint(path_, other).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("ppo"));
}

TEST_F(CheckpointErrorTest, UnwritableDirectoryIsAnErrorAndLeavesNoFile) {
  const std::string path = TempFile("no/such/dir/checkpoint.pt");
  EXPECT_FALSE(WriteCheckpoint(path, *learner_, {}).ok());
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(CheckpointListTest, ListsByVersionAndPrunesTheOldest) {
  const std::string dir = TempFile("listing");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  for (int64_t v : {9, 10, 100000000, 2}) {
    std::ofstream(CheckpointPath(dir, v)) << "x";
  }
  std::ofstream(dir + "/checkpoint-00000011.pt.tmp") << "torn";
  std::ofstream(dir + "/notes.txt") << "n";
  EXPECT_THAT(ListCheckpoints(dir),
              ::testing::ElementsAre(
                  CheckpointPath(dir, 2), CheckpointPath(dir, 9),
                  CheckpointPath(dir, 10), CheckpointPath(dir, 100000000)));
  ASSERT_TRUE(PruneCheckpoints(dir, 2).ok());
  EXPECT_THAT(ListCheckpoints(dir),
              ::testing::ElementsAre(CheckpointPath(dir, 10),
                                     CheckpointPath(dir, 100000000)));
}

}  // namespace
}  // namespace vantage
