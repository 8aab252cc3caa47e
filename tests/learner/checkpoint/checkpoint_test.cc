#include "learner/checkpoint/checkpoint.h"

#include <ATen/ATen.h>
#include <torch/serialize/archive.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "absl/strings/str_cat.h"
#include "actor/actor_core.h"
#include "common/nn/networks.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/algorithms/trpo/trpo_config.h"
#include "tests/fakes/learner_batches.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

constexpr int64_t kHorizon = kTestHorizon;

// ctest runs the cases of one suite as parallel processes (-j2): each
// process gets a directory of its own (removed when it ends), or two
// fixtures write the same checkpoint at once.
const std::string& TestDirectory() {
  static const auto* directory = [] {
    auto* path = new std::string(
        absl::StrCat(::testing::TempDir(), "/checkpoint_test_", ::getpid()));
    std::filesystem::create_directories(*path);
    return path;
  }();
  return *directory;
}

class RemoveTestDirectory : public ::testing::Environment {
 public:
  void TearDown() override { std::filesystem::remove_all(TestDirectory()); }
};
::testing::Environment* const kRemoveTestDirectory =
    ::testing::AddGlobalTestEnvironment(new RemoveTestDirectory);

std::string TempFile(const std::string& name) {
  return absl::StrCat(TestDirectory(), "/", name);
}

LearnerConfig Config(const EnvSpec& spec, const std::string& algorithm) {
  return TestLearnerConfig(spec, algorithm);
}

class CheckpointTest : public ::testing::TestWithParam<std::string> {};

// A learner read back from a checkpoint is the learner that wrote it: same
// weights, normaliser, version and counters now, and, given the same
// segments, the same next update (which needs the optimiser's moments, the
// reward scaler and the minibatch generator to have come back too).
TEST_P(CheckpointTest, RoundTripRestoresTheWholeLearner) {
  auto actor = MakeTestActor(GetParam() == "a2c" ? 60 : kHorizon, "Hopper",
                             TestNetwork(GetParam()));
  const LearnerConfig config = Config(actor->spec(), GetParam());
  auto learner = *LearnerCore::Create(config);
  for (int i = 0; i < 2; ++i)
    UpdateWith(*learner, ActOneBatch(*actor, *learner));
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

  const std::vector<Segment> next = ActOneBatch(*actor, *learner);
  const UpdateStats a = UpdateWith(*learner, next);
  const UpdateStats b = UpdateWith(**restored, next);
  EXPECT_EQ(a.algorithm.policy_loss, b.algorithm.policy_loss);
  EXPECT_EQ(a.algorithm.value_loss, b.algorithm.value_loss);
  EXPECT_EQ(a.biased_fraction, b.biased_fraction);
  EXPECT_EQ(a.episodes, b.episodes);
  ExpectSameWeights(*learner, **restored);
}

INSTANTIATE_TEST_SUITE_P(Algorithms, CheckpointTest,
                         ::testing::Values("ppo", "a2c", "trpo", "ppo_gru"));

class CheckpointErrorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    actor_ = MakeTestActor();
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

// Networks are never reinitialised to fit a config: a feed-forward
// policy's checkpoint does not take a core, nor a GRU's another one.
TEST_F(CheckpointErrorTest, AnotherCoreIsRefusedByName) {
  LearnerConfig gru = config_;
  gru.network = TestNetwork("ppo_gru");
  absl::Status status = ReadCheckpoint(path_, gru).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("checkpoint's policy has core none, but the run "
                        "config says gru:16 (--core, --core_size)"));
  const std::string gru_path = TempFile("gru.pt");
  ASSERT_TRUE(WriteCheckpoint(gru_path, **LearnerCore::Create(gru), {}).ok());
  EXPECT_TRUE(ReadCheckpoint(gru_path, gru).ok());
  status = ReadCheckpoint(gru_path, config_).status();
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("has core gru:16, but the run config says none"));
  LearnerConfig lstm = gru;
  lstm.network.core = Core::kLstm;
  status = ReadCheckpoint(gru_path, lstm).status();
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("has core gru:16, but the run config says lstm:16"));
}

TEST_F(CheckpointErrorTest, AnEx2RunDoesNotContinueARunWithoutIt) {
  LearnerConfig other = config_;
  other.exploration.ex2 = Ex2Config();
  const absl::Status status = ReadCheckpoint(path_, other).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("'ex2.pool.rows'"));
  EXPECT_THAT(std::string(status.message()), HasSubstr("without EX2"));
}

TEST_F(CheckpointErrorTest, ALinearBaselineRunDoesNotContinueARunWithoutIt) {
  const LearnerConfig trpo = Config(actor_->spec(), "trpo");
  const std::string path = TempFile("value_network_trpo.pt");
  ASSERT_TRUE(WriteCheckpoint(path, **LearnerCore::Create(trpo), {}).ok());
  LearnerConfig linear = trpo;
  linear.algorithm.Mutable<TrpoConfig>().linear_baseline = true;
  const absl::Status status = ReadCheckpoint(path, linear).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("checkpoint entry 'linear_critic' is missing"));
  const std::string linear_path = TempFile("linear_trpo.pt");
  ASSERT_TRUE(
      WriteCheckpoint(linear_path, **LearnerCore::Create(linear), {}).ok());
  EXPECT_TRUE(ReadCheckpoint(linear_path, linear).ok());
}

TEST_F(CheckpointErrorTest, AnotherAlgorithmIsRefused) {
  LearnerConfig other = config_;
  other.algorithm.name = "trpo";
  const absl::Status status = ReadCheckpoint(path_, other).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("ppo"));
}

std::string ReadAll(const std::string& path) {
  std::stringstream read;
  read << std::ifstream(path, std::ios::binary).rdbuf();
  return read.str();
}

// Every read of a checkpoint (the learner, and the extras a resume reads
// first) refuses `bytes` as damaged, naming the file and `why`.
void ExpectDamaged(const std::string& bytes, const std::string& name,
                   const LearnerConfig& config, const std::string& why) {
  const std::string path = TempFile(name);
  std::ofstream(path, std::ios::binary) << bytes;
  for (const absl::Status& status : {ReadCheckpoint(path, config).status(),
                                     ReadCheckpointExtras(path).status()}) {
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
    EXPECT_THAT(std::string(status.message()),
                HasSubstr("checkpoint " + path + " is damaged"));
    EXPECT_THAT(std::string(status.message()), HasSubstr(why));
  }
}

// A checkpoint carries the TorchScript of its archives' module types, which
// LibTorch compiles while loading without checking any zip CRC; some corrupt
// sources crash its parser (found by tests/fuzz/checkpoint_fuzzer). The
// CRC-32 check refuses them before LibTorch reads anything.
TEST_F(CheckpointErrorTest, BrokenArchiveCodeIsRefused) {
  std::string bytes = ReadAll(path_);
  const size_t code = bytes.find("class Module(Module):");
  ASSERT_NE(code, std::string::npos);
  bytes[code] = ';';
  ExpectDamaged(bytes, "broken_code.pt", config_, "fails its CRC-32 check");
}

// One flipped bit in a weight used to load silently as another weight.
TEST_F(CheckpointErrorTest, AFlippedBitInAWeightIsRefused) {
  at::Tensor largest;  // a weight matrix: random, so its bytes are unique
  for (const at::Tensor& parameter : learner_->CurrentWeights().parameters) {
    if (!largest.defined() || parameter.numel() > largest.numel()) {
      largest = parameter.contiguous();
    }
  }
  const std::string weights(reinterpret_cast<const char*>(largest.data_ptr()),
                            largest.numel() * largest.element_size());
  std::string bytes = ReadAll(path_);
  const size_t at = bytes.find(weights);
  ASSERT_NE(at, std::string::npos);
  bytes[at + weights.size() / 2] ^= 0x01;
  ExpectDamaged(bytes, "flipped_weight.pt", config_, "fails its CRC-32 check");
}

// A copy cut short (a full disk, an interrupted transfer): refused as a
// damaged archive, or, when only the end record's tail is missing (every
// entry and the zip64 directory intact), by LibTorch's reader.
TEST_F(CheckpointErrorTest, ATruncatedCopyIsRefused) {
  const std::string bytes = ReadAll(path_);
  ExpectDamaged(bytes.substr(0, bytes.size() / 2), "truncated.pt", config_,
                "not a zip archive");
  const std::string path = TempFile("end_record_cut.pt");
  std::ofstream(path, std::ios::binary) << bytes.substr(0, bytes.size() - 10);
  for (const absl::Status& status : {ReadCheckpoint(path, config_).status(),
                                     ReadCheckpointExtras(path).status()}) {
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << status;
    EXPECT_THAT(std::string(status.message()), HasSubstr(path));
  }
}

// A learner publishes the weights it loads, and it must never publish
// non-finite ones. Found by tests/fuzz/checkpoint_entries_fuzzer.
TEST_F(CheckpointErrorTest, NonFiniteWeightsAreRefused) {
  torch::serialize::OutputArchive archive;
  learner_->Save(archive);
  PolicyNetwork policy(config_.spec, config_.network);
  const auto first = policy->named_parameters()[0];
  at::Tensor poisoned = first.value().detach().clone();
  poisoned.view(-1)[0] = std::nan("");
  const std::string entry = "policy." + first.key();
  archive.write(entry, poisoned);
  const std::string path = TempFile("non_finite.pt");
  archive.save_to(path);
  const absl::Status status = ReadCheckpoint(path, config_).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr(entry));
  EXPECT_THAT(std::string(status.message()), HasSubstr("non-finite"));
}

// Six counters in two rows once reached item() on a row and aborted the
// process. Found by tests/fuzz/checkpoint_entries_fuzzer.
TEST_F(CheckpointErrorTest, CountersOfAnotherShapeAreRefused) {
  torch::serialize::OutputArchive archive;
  learner_->Save(archive);
  archive.write("counters", at::zeros({2, 3}, at::kLong));
  const std::string path = TempFile("counters_2x3.pt");
  archive.save_to(path);
  const absl::Status status = ReadCheckpoint(path, config_).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()), HasSubstr("'counters'"));
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
