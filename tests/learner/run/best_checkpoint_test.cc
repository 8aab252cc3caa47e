#include "learner/run/best_checkpoint.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string FreshDirectory(const std::string& name) {
  const std::string path = std::string(::testing::TempDir()) + "/" + name;
  fs::remove_all(path);
  fs::create_directories(path);
  return path;
}

// A stand-in for the checkpoint of `version`, whose bytes name it.
std::string WriteCheckpoint(const std::string& dir, int64_t version) {
  const std::string path = dir + "/checkpoint-" + std::to_string(version);
  std::ofstream(path) << "version " << version;
  return path;
}

std::string Read(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

EvaluationSummary Evaluated(int64_t version, double mean) {
  EvaluationSummary summary;
  summary.version = version;
  summary.mean = summary.min = summary.max = mean;
  return summary;
}

TEST(BestCheckpointTest, KeepsTheVersionWithTheHighestMeanReturn) {
  const std::string dir = FreshDirectory("best_keeps");
  absl::StatusOr<BestCheckpoint> best = BestCheckpoint::Open(dir);
  ASSERT_TRUE(best.ok()) << best.status();
  EXPECT_TRUE(std::isnan(best->best_return()));
  for (const auto& [version, mean, kept] :
       {std::tuple{2, 10.0, true}, std::tuple{4, 30.0, true},
        std::tuple{6, 20.0, false}, std::tuple{8, 30.0, false}}) {
    ASSERT_TRUE(best->Hold(WriteCheckpoint(dir, version), version).ok());
    absl::StatusOr<bool> offered = best->Offer(Evaluated(version, mean));
    ASSERT_TRUE(offered.ok()) << offered.status();
    EXPECT_EQ(*offered, kept) << version;
    // Kept or not, nothing stays held.
    EXPECT_FALSE(fs::exists(best->held_path(version))) << version;
    // The run's own checkpoint is untouched.
    EXPECT_EQ(Read(dir + "/checkpoint-" + std::to_string(version)),
              "version " + std::to_string(version));
  }
  EXPECT_EQ(Read(best->best_path()), "version 4");
  EXPECT_THAT(Read(dir + "/best.json"), HasSubstr("\"version\": 4,"));
  EXPECT_EQ(best->best_return(), 30.0);
}

// A resumed run knows the best so far, and what an earlier life held for
// evaluations that never came is gone.
TEST(BestCheckpointTest, AResumedRunContinuesFromBestJson) {
  const std::string dir = FreshDirectory("best_resumed");
  {
    absl::StatusOr<BestCheckpoint> best = BestCheckpoint::Open(dir);
    ASSERT_TRUE(best.ok());
    ASSERT_TRUE(best->Hold(WriteCheckpoint(dir, 2), 2).ok());
    ASSERT_TRUE(best->Offer(Evaluated(2, 50.0)).ok());
    ASSERT_TRUE(best->Hold(WriteCheckpoint(dir, 4), 4).ok());
  }
  absl::StatusOr<BestCheckpoint> best = BestCheckpoint::Open(dir);
  ASSERT_TRUE(best.ok()) << best.status();
  EXPECT_EQ(best->best_return(), 50.0);
  EXPECT_FALSE(fs::exists(best->held_path(4)));
  ASSERT_TRUE(best->Hold(WriteCheckpoint(dir, 6), 6).ok());
  ASSERT_TRUE(best->Offer(Evaluated(6, 40.0)).ok());
  EXPECT_EQ(Read(best->best_path()), "version 2");
}

// Evaluations come in version order: one of version 6 releases a held 4
// that a newer version overtook before it was evaluated.
TEST(BestCheckpointTest, AnEvaluationReleasesOlderHeldVersions) {
  const std::string dir = FreshDirectory("best_release");
  absl::StatusOr<BestCheckpoint> best = BestCheckpoint::Open(dir);
  ASSERT_TRUE(best.ok());
  ASSERT_TRUE(best->Hold(WriteCheckpoint(dir, 4), 4).ok());
  ASSERT_TRUE(best->Hold(WriteCheckpoint(dir, 6), 6).ok());
  ASSERT_TRUE(best->Offer(Evaluated(6, 1.0)).ok());
  EXPECT_FALSE(fs::exists(best->held_path(4)));
  EXPECT_EQ(Read(best->best_path()), "version 6");
}

TEST(BestCheckpointTest, RefusesWhatItCannotStandBy) {
  const std::string dir = FreshDirectory("best_refuses");
  absl::StatusOr<BestCheckpoint> best = BestCheckpoint::Open(dir);
  ASSERT_TRUE(best.ok());
  // Nothing held for version 3: nothing changes.
  absl::StatusOr<bool> unheld = best->Offer(Evaluated(3, 1.0));
  EXPECT_EQ(unheld.status().code(), absl::StatusCode::kNotFound);
  EXPECT_THAT(std::string(unheld.status().message()), HasSubstr("version 3"));
  EXPECT_FALSE(fs::exists(best->best_path()));
  // A missing run checkpoint cannot be held.
  EXPECT_FALSE(best->Hold(dir + "/checkpoint-missing", 5).ok());
  // A non-finite mean never becomes the best.
  ASSERT_TRUE(best->Hold(WriteCheckpoint(dir, 7), 7).ok());
  absl::StatusOr<bool> nan = best->Offer(Evaluated(7, std::nan("")));
  ASSERT_TRUE(nan.ok());
  EXPECT_FALSE(*nan);
  // A damaged best.json is named, not taken for "no best yet".
  std::ofstream(dir + "/best.json") << "{\"version\": 2}";
  absl::StatusOr<BestCheckpoint> damaged = BestCheckpoint::Open(dir);
  EXPECT_EQ(damaged.status().code(), absl::StatusCode::kDataLoss);
  EXPECT_THAT(std::string(damaged.status().message()), HasSubstr("best.json"));
}

}  // namespace
}  // namespace vantage
