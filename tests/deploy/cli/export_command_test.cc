// `vantage export` from a trained run's directory: the model file written
// whole, and every refusal naming what: a missing or corrupt checkpoint, a
// policy the exporter cannot express, missing flags.

#include <filesystem>
#include <fstream>
#include <string>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::string FreshPath(const std::string& name) {
  const std::string path = absl::StrCat(::testing::TempDir(), "/export_", name);
  std::filesystem::remove_all(path);
  return path;
}

// A short local run of InvertedPendulum (`extra` flags added), its
// directory.
std::string TrainedRun(const std::string& name, const std::string& extra) {
  const std::string run = FreshPath(name);
  const Outcome trained = RunVantage(absl::StrCat(
      "train --mode=local --steps=2048 --horizon=1024 --run_dir=", run, " ",
      extra));
  EXPECT_EQ(trained.exit_code, 0) << trained.err;
  return run;
}

TEST(ExportCommandTest, WritesTheNewestCheckpointsPolicy) {
  const std::string run = TrainedRun("plain", "");
  const std::string model = FreshPath("policy.onnx");
  const Outcome exported = RunVantage(absl::StrCat(
      "export --checkpoint=", run, " --out=", model, " --distribution"));
  ASSERT_EQ(exported.exit_code, 0) << exported.err;
  EXPECT_THAT(exported.out,
              HasSubstr("export: " + model + " (policy version 2"));
  EXPECT_GT(std::filesystem::file_size(model), 1000u);
  EXPECT_FALSE(std::filesystem::exists(model + ".tmp"));
}

TEST(ExportCommandTest, EveryRefusalNamesWhat) {
  const std::string model = FreshPath("refused.onnx");
  Outcome outcome = RunVantage(absl::StrCat("export --out=", model));
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("--checkpoint is required"));
  const std::string missing = FreshPath("no_such_run");
  outcome = RunVantage(
      absl::StrCat("export --checkpoint=", missing, " --out=", model));
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr(missing));
  const std::string garbage = FreshPath("garbage.pt");
  std::ofstream(garbage) << "not a checkpoint";
  outcome = RunVantage(
      absl::StrCat("export --checkpoint=", garbage, " --out=", model));
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr(garbage));
  // A recurrent policy: rollout acts with it (its state carried through
  // each episode), export refuses it by name.
  const std::string gru = TrainedRun("gru", "--core=gru --core_size=16");
  outcome = RunVantage(
      absl::StrCat("rollout --checkpoint=", gru, " --episodes=2 --seed=3"));
  EXPECT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(outcome.out, HasSubstr("RESULT rollout"));
  outcome =
      RunVantage(absl::StrCat("export --checkpoint=", gru, " --out=", model));
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("the policy has a recurrent core (gru)"));
  EXPECT_FALSE(std::filesystem::exists(model));
}

}  // namespace
}  // namespace vantage
