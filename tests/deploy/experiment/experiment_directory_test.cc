#include "deploy/experiment/experiment_directory.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "deploy/cli/experiment_command.h"
#include "deploy/experiment/experiment_grid.h"
#include "deploy/run/run_config.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::string Fresh(const std::string& name) {
  const std::string path = absl::StrCat(
      std::filesystem::temp_directory_path().string(), "/vantage-expdir-",
      ::testing::UnitTest::GetInstance()->current_test_info()->name(), "-",
      name);
  std::filesystem::remove_all(path);
  return path;
}

pb::ExpandedExperiment Expand(const std::string& seeds, double budget = 1) {
  absl::StatusOr<pb::Experiment> experiment = ParseExperimentJson(
      absl::StrCat(R"({"base": {"mode": "local", "training": {"steps": "2048"}},
                      "seeds": )",
                   seeds, R"(, "variants": [{"set": {"estimator": "max"}},
                                             {"set": {"estimator": "gae"}}]})"),
      "test.json");
  EXPECT_TRUE(experiment.ok()) << experiment.status();
  ExpandOptions options;
  options.file = "test.json";
  options.budget = budget;
  absl::StatusOr<pb::ExpandedExperiment> expanded =
      ExpandExperiment(*experiment, options, ExperimentRunSchema());
  EXPECT_TRUE(expanded.ok()) << expanded.status();
  return *expanded;
}

void Write(const std::string& path, const std::string& text) {
  std::filesystem::create_directories(
      std::filesystem::path(path).parent_path());
  std::ofstream(path) << text;
}

TEST(ExperimentDirectoryTest, LaterRunsExtendTheRecord) {
  const ExperimentDirectory directory(Fresh("extend"));
  ASSERT_TRUE(directory.Prepare(Expand("[0]"), pb::RunConfig()).ok());
  // More seeds later, or a subset (--only): the record keeps every cell.
  ASSERT_TRUE(directory.Prepare(Expand("[1, 0]"), pb::RunConfig()).ok());
  absl::StatusOr<pb::ExpandedExperiment> merged =
      directory.Merged(Expand("[2]"));
  ASSERT_TRUE(merged.ok()) << merged.status();
  std::vector<std::string> dirs;
  for (const pb::ExperimentCell& cell : merged->cells()) {
    dirs.push_back(cell.dir());
  }
  EXPECT_THAT(dirs, ::testing::ElementsAre(
                        "InvertedPendulum/max-rho0.4-E1-16-64-2048/seed-0",
                        "InvertedPendulum/gae/seed-0",
                        "InvertedPendulum/max-rho0.4-E1-16-64-2048/seed-1",
                        "InvertedPendulum/gae/seed-1",
                        "InvertedPendulum/max-rho0.4-E1-16-64-2048/seed-2",
                        "InvertedPendulum/gae/seed-2"));
}

TEST(ExperimentDirectoryTest, AnotherBudgetOrOtherSettingsAreRefused) {
  const ExperimentDirectory directory(Fresh("refuse"));
  ASSERT_TRUE(directory.Prepare(Expand("[0]"), pb::RunConfig()).ok());
  const absl::Status budget =
      directory.Prepare(Expand("[1]", 0.5), pb::RunConfig());
  EXPECT_EQ(budget.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(budget.message(),
              HasSubstr("holds cells run at --budget=1; this run asks for "
                        "0.5"));
  // A run directory made with other settings than its cell's.
  pb::ExpandedExperiment other = Expand("[0]");
  other.mutable_cells(1)->mutable_config()->mutable_training()->set_steps(7);
  Write(directory.RunDir(other.cells(1)) + "/config.json",
        RunConfigToJson(other.cells(1).config()));
  const absl::Status runs = directory.CheckRuns(Expand("[0]"));
  EXPECT_EQ(runs.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(runs.message(), HasSubstr("gae/seed-0 holds a run made with "
                                        "other settings"));
  EXPECT_THAT(runs.message(), HasSubstr("steps"));
  const absl::Status record = directory.Merged(other).status();
  EXPECT_EQ(record.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(record.message(),
              HasSubstr("records InvertedPendulum/gae/seed-0 with other "
                        "settings"));
}

// A vantage older than a setting wrote records without it: they go on
// with the setting's default and are refused where that default is not
// what the cell asks for.
TEST(ExperimentDirectoryTest, RecordsFromBeforeASettingExistedTakeItsDefault) {
  const ExperimentDirectory directory(Fresh("older"));
  pb::ExpandedExperiment older = Expand("[0]");
  for (pb::ExperimentCell& cell : *older.mutable_cells()) {
    cell.mutable_config()->mutable_training()->clear_frame_stack();
  }
  ASSERT_TRUE(directory.Prepare(older, pb::RunConfig()).ok());
  for (const pb::ExperimentCell& cell : older.cells()) {
    Write(directory.RunDir(cell) + "/config.json",
          RunConfigToJson(cell.config()));
  }
  const absl::Status now = directory.Prepare(Expand("[0]"), pb::RunConfig());
  EXPECT_TRUE(now.ok()) << now;

  // Without its estimator, the max cell's record reads as gae's.
  pb::ExpandedExperiment unnamed = Expand("[0]");
  unnamed.mutable_cells(0)
      ->mutable_config()
      ->mutable_advantage()
      ->clear_estimator();
  Write(directory.RunDir(unnamed.cells(0)) + "/config.json",
        RunConfigToJson(unnamed.cells(0).config()));
  const absl::Status runs = directory.CheckRuns(Expand("[0]"));
  EXPECT_EQ(runs.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(runs.message(), HasSubstr("estimator"));
  const ExperimentDirectory record(Fresh("older-record"));
  ASSERT_TRUE(record.Prepare(unnamed, pb::RunConfig()).ok());
  const absl::Status merged = record.Merged(Expand("[0]")).status();
  EXPECT_EQ(merged.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(merged.message(), HasSubstr("with other settings"));
}

// The record is committed beside a grid's cells: the same cells must write
// the same bytes, whatever order their maps were filled in.
TEST(ExperimentDirectoryTest, TheRecordListsEveryMapInKeyOrder) {
  const std::vector<std::string> keys = {"a", "b", "c", "d", "e",
                                         "f", "g", "h", "i", "j"};
  pb::ExpandedExperiment experiment;
  for (int cell = 0; cell < 20; ++cell) {
    pb::ExperimentCell& added = *experiment.add_cells();
    for (size_t i = 0; i < keys.size(); ++i) {
      // Each cell inserts its keys from another starting point.
      const std::string& key = keys[(i + cell) % keys.size()];
      (*added.mutable_flags())[key] = key;
      (*added.mutable_origins())[key] = key;
    }
  }
  const std::string json = ExpandedExperimentToJson(experiment);
  size_t at = 0;
  for (int map = 0; map < 2 * experiment.cells_size(); ++map) {
    for (const std::string& key : keys) {
      const size_t found = json.find(absl::StrCat("\"", key, "\": "), at);
      ASSERT_NE(found, std::string::npos)
          << "map " << map << " lists " << key << " out of order:\n"
          << json;
      at = found;
    }
  }
  EXPECT_EQ(json, ExpandedExperimentToJson(experiment));
}

TEST(ExperimentDirectoryTest, ACellsStateComesFromItsRunDirectory) {
  const ExperimentDirectory directory(Fresh("states"));
  const pb::ExperimentCell cell = Expand("[0]").cells(0);
  const std::string run = directory.RunDir(cell);
  EXPECT_EQ(directory.Inspect(cell).state, CellState::kNew);
  Write(run + "/config.json", RunConfigToJson(cell.config()));
  Write(run + "/progress.csv",
        "env_steps,updates,mean_return\n1024,1,5\n2048,2,7\n");
  EXPECT_EQ(directory.Inspect(cell).state, CellState::kFinished);
  // A torn last row (a killed run) does not finish it.
  Write(run + "/progress.csv",
        "env_steps,updates,mean_return\n1024,1,5\n2048,2\n");
  CellStatus status = directory.Inspect(cell);
  EXPECT_EQ(status.state, CellState::kNoCheckpoint);
  EXPECT_EQ(status.env_steps, 1024);
  Write(run + "/checkpoints/checkpoint-00000001.pt", "x");
  EXPECT_EQ(directory.Inspect(cell).state, CellState::kResumable);
  // A run without a checkpoint starts again from nothing; its log stays.
  Write(run + "/train.log", "log\n");
  ASSERT_TRUE(directory.ClearRun(cell).ok());
  EXPECT_EQ(directory.Inspect(cell).state, CellState::kNew);
  EXPECT_TRUE(std::filesystem::exists(run + "/train.log"));
  EXPECT_FALSE(std::filesystem::exists(run + "/checkpoints"));
}

}  // namespace
}  // namespace vantage
