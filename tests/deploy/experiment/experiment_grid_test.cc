#include "deploy/experiment/experiment_grid.h"

#include <filesystem>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "deploy/cli/experiment_command.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

absl::StatusOr<pb::ExpandedExperiment> Expand(const std::string& json,
                                              ExpandOptions options = {}) {
  options.file = options.file.empty() ? "test.json" : options.file;
  absl::StatusOr<pb::Experiment> experiment =
      ParseExperimentJson(json, options.file);
  if (!experiment.ok()) return experiment.status();
  return ExpandExperiment(*experiment, options, ExperimentRunSchema());
}

std::vector<std::string> Dirs(const pb::ExpandedExperiment& expanded) {
  std::vector<std::string> dirs;
  for (const pb::ExperimentCell& cell : expanded.cells()) {
    dirs.push_back(cell.dir());
  }
  return dirs;
}

std::string ErrorOf(const std::string& json, ExpandOptions options = {}) {
  absl::StatusOr<pb::ExpandedExperiment> expanded = Expand(json, options);
  EXPECT_FALSE(expanded.ok()) << "expanded: " << json;
  EXPECT_EQ(expanded.status().code(), absl::StatusCode::kInvalidArgument);
  return std::string(expanded.status().message());
}

constexpr char kBase[] =
    R"("base": {"mode": "local", "training": {"steps": "10000"}})";

TEST(ExperimentGridTest, AxesTimesVariantsTimesSeeds) {
  absl::StatusOr<pb::ExpandedExperiment> expanded =
      Expand(absl::StrCat("{", kBase, R"(, "seeds": [3, 4],
      "axes": [{"flag": "env", "values": ["InvertedPendulum", "Hopper"]}],
      "variants": [
        {"axes": [{"flag": "estimator", "values": ["max", "order:2"]}]},
        {"set": {"estimator": "gae"}}]})"));
  ASSERT_TRUE(expanded.ok()) << expanded.status();
  EXPECT_THAT(
      Dirs(*expanded),
      ElementsAre("InvertedPendulum/max-rho0.4-E1-16-64-2048/seed-3",
                  "InvertedPendulum/max-rho0.4-E1-16-64-2048/seed-4",
                  "InvertedPendulum/order2-rho0.4-E1-16-64-2048/seed-3",
                  "InvertedPendulum/order2-rho0.4-E1-16-64-2048/seed-4",
                  "Hopper/max-rho0.4-E1-16-64-2048/seed-3",
                  "Hopper/max-rho0.4-E1-16-64-2048/seed-4",
                  "Hopper/order2-rho0.4-E1-16-64-2048/seed-3",
                  "Hopper/order2-rho0.4-E1-16-64-2048/seed-4",
                  "InvertedPendulum/gae/seed-3", "InvertedPendulum/gae/seed-4",
                  "Hopper/gae/seed-3", "Hopper/gae/seed-4"));
  const pb::ExperimentCell& cell = expanded->cells(2);
  EXPECT_EQ(cell.env(), "InvertedPendulum");
  EXPECT_EQ(cell.group(), "order2-rho0.4-E1-16-64-2048");
  EXPECT_EQ(cell.seed(), 3u);
  // The resolved config is the run's: base, settings and defaults.
  EXPECT_EQ(cell.config().advantage().estimator(), "order:2");
  EXPECT_EQ(cell.config().training().seed(), 3u);
  EXPECT_EQ(cell.config().training().steps(), 10000);
  EXPECT_EQ(cell.config().mode(), "local");
  EXPECT_EQ(cell.flags().at("estimator"), "order:2");
  EXPECT_EQ(cell.origins().at("estimator"), "variants[0].axes[0].values[1]");
  EXPECT_EQ(cell.origins().at("env"), "axes[0].values[0]");
  EXPECT_EQ(expanded->report().baseline(), "gae");
}

TEST(ExperimentGridTest, PointsSetFlagsTogetherAndOtherSettingsNameGroups) {
  absl::StatusOr<pb::ExpandedExperiment> expanded =
      Expand(absl::StrCat("{", kBase, R"(, "seeds": [0],
      "axes": [{"points": [
        {"flags": {"env": "PointMaze", "ensemble": "1,16,500", "rho": "0.5"}},
        {"flags": {"env": "Hopper", "horizon": "1024"}}]}],
      "variants": [{"set": {"estimator": "max", "ppo_epochs": "3"}}]})"));
  ASSERT_TRUE(expanded.ok()) << expanded.status();
  EXPECT_THAT(
      Dirs(*expanded),
      ElementsAre("PointMaze/max-rho0.5-E1-16-500-ppo_epochs_3/seed-0",
                  // horizon came with the env: not in the name.
                  "Hopper/max-rho0.4-E1-16-64-2048-ppo_epochs_3/seed-0"));
  EXPECT_EQ(expanded->cells(1).config().training().horizon(), 1024);
  EXPECT_EQ(expanded->cells(1).config().ppo().epochs(), 3);
}

TEST(ExperimentGridTest, BudgetScalesStepsAndSeedsFlagReplacesTheFilesSeeds) {
  ExpandOptions options;
  options.budget = 0.25;
  options.seeds = {7};
  absl::StatusOr<pb::ExpandedExperiment> expanded =
      Expand(absl::StrCat("{", kBase, R"(, "seeds": [0, 1],
        "axes": [{"flag": "steps", "values": ["10000", "1"]}]})"),
             options);
  ASSERT_TRUE(expanded.ok()) << expanded.status();
  ASSERT_EQ(expanded->cells_size(), 2);
  EXPECT_EQ(expanded->cells(0).config().training().steps(), 2500);
  // Rounded, and never below one step.
  EXPECT_EQ(expanded->cells(1).config().training().steps(), 1);
  EXPECT_EQ(expanded->cells(0).flags().at("steps"), "2500");
  EXPECT_EQ(expanded->cells(0).origins().at("steps"), "--budget");
  EXPECT_EQ(expanded->cells(0).seed(), 7u);
  EXPECT_EQ(expanded->cells(0).origins().at("seed"), "--seeds");
  EXPECT_EQ(expanded->budget(), 0.25);
}

TEST(ExperimentGridTest, EveryRuleBrokenNamesTheField) {
  const std::string base = absl::StrCat("{", kBase, R"(, "seeds": [0], )");
  EXPECT_THAT(
      ErrorOf(base + R"("axes": [{"flag": "estimatr", "values": ["max"]}]})"),
      HasSubstr("test.json: axes[0].flag: 'estimatr' is not a run flag"));
  EXPECT_THAT(ErrorOf(base + R"("axes": [{"flag": "rho", "values": ["0.1"],
                                 "points": [{"flags": {"rho": "0.2"}}]}]})"),
              HasSubstr("axes[0]: give either flag and values, or points"));
  EXPECT_THAT(ErrorOf(base + R"("axes": [{"flag": "rho"}]})"),
              HasSubstr("axes[0].values: list at least one value"));
  EXPECT_THAT(ErrorOf(base + R"("axes": [{"points": [{}]}]})"),
              HasSubstr("axes[0].points[0]: a point sets at least one flag"));
  EXPECT_THAT(ErrorOf(base + R"("variants": [{"set": {"seed": "1"}}]})"),
              HasSubstr("variants[0].set.seed: seeds are the experiment's"));
  EXPECT_THAT(ErrorOf(base + R"("variants": [{"set": {"run_dir": "x"}}]})"),
              HasSubstr("variants[0].set.run_dir: --run_dir is the runner's"));
  EXPECT_THAT(
      ErrorOf(base + R"("axes": [{"flag": "rho", "values": ["0.5", "2"]}]})"),
      HasSubstr("the cell of axes[0].values[1], seed 0: "));
  EXPECT_THAT(
      ErrorOf(base + R"("axes": [{"flag": "rho", "values": ["0.5", "2"]}]})"),
      HasSubstr("rho"));
  EXPECT_THAT(
      ErrorOf(base + R"("axes": [{"flag": "ppo_epochs", "values": ["x"]}]})"),
      HasSubstr("--ppo_epochs 'x' is not an integer"));
  EXPECT_THAT(
      ErrorOf(base + R"("axes": [{"flag": "estimator", "values": ["gae"]},
                                          {"flag": "rho", "values": ["0.2", "0.4"]}]})"),
      HasSubstr("two cells are both InvertedPendulum/gae/seed-0"));
  EXPECT_THAT(ErrorOf(base + R"("axes": [{"flag": "rho", "values": ["0.2"]}],
                                 "variants": [{"set": {"rho": "0.3"}}]})"),
              HasSubstr("axes[0].values[0] and variants[0].set.rho both set "
                        "--rho in one cell"));
  EXPECT_THAT(ErrorOf(base + R"("report": {"thresholds": {"Hoper": 1}}})"),
              HasSubstr("report.thresholds.Hoper: no cell of this experiment "
                        "runs Hoper (its envs: InvertedPendulum)"));
  EXPECT_THAT(ErrorOf(absl::StrCat("{", kBase, "}")),
              HasSubstr("test.json: seeds: list at least one seed"));
  EXPECT_THAT(ErrorOf(absl::StrCat("{", kBase, R"(, "seeds": [1, 1]})")),
              HasSubstr("seeds: a seed is listed twice"));
  ExpandOptions no_budget;
  no_budget.budget = 0;
  EXPECT_THAT(ErrorOf(base + "}", no_budget),
              HasSubstr("--budget must be a number > 0"));
  EXPECT_THAT(ErrorOf(R"({"base": {"training": {"stepz": 1}}, "seeds": [0]})"),
              HasSubstr("test.json: "));
  EXPECT_THAT(ErrorOf(R"({"axis": []})"), HasSubstr("test.json: "));
}

// Every preset is a valid experiment (its cells resolve as `vantage train`
// would resolve them).
TEST(ExperimentGridTest, EveryPresetExpands) {
  int presets = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator("configs/experiments")) {
    if (entry.path().extension() != ".json") continue;
    ++presets;
    absl::StatusOr<pb::Experiment> experiment =
        ReadExperimentFile(entry.path().string());
    ASSERT_TRUE(experiment.ok()) << experiment.status();
    ExpandOptions options;
    options.file = entry.path().string();
    options.budget = 0.1;
    absl::StatusOr<pb::ExpandedExperiment> expanded =
        ExpandExperiment(*experiment, options, ExperimentRunSchema());
    ASSERT_TRUE(expanded.ok()) << expanded.status();
    EXPECT_GT(expanded->cells_size(), 1) << entry.path();
    EXPECT_FALSE(experiment->description().empty()) << entry.path();
  }
  EXPECT_GE(presets, 5);
}

}  // namespace
}  // namespace vantage
