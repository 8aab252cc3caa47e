// What `vantage train` and `vantage learner` refuse before anything runs,
// checked in-process against the code the commands call (ResolveRunRequest,
// CheckRunCanStart); train_command_test checks that a refusal is one line
// on stderr and exit code 2.

#include "deploy/cli/run_request.h"

#include <filesystem>
#include <string>
#include <utility>

#include "deploy/cli/train_command.h"
#include "deploy/run_config.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

RunRequest FromJson(const std::string& json) {
  absl::StatusOr<pb::RunConfig> flags = ParseRunConfigJson(json);
  EXPECT_TRUE(flags.ok()) << flags.status();
  RunRequest request;
  if (flags.ok()) request.flags = *flags;
  return request;
}

TEST(RunRequestTest, BadSettingsNameTheirFlag) {
  const std::pair<std::string, std::string> cases[] = {
      {R"({"algo": "sac"})",
       "--algo: unknown algorithm 'sac'; available: a2c, ppo, trpo"},
      {R"({"mode": "cluster"})", "--mode: unknown mode 'cluster'"},
      {R"({"estimator": "median"})", "unknown statistic 'median'"},
      {R"({"rho": 1.5})", "rho must be in [0, 1]"},
      {R"({"steps": 0})", "--steps must be >= 1"},
      {R"({"envs": 0})", "--envs must be in [1, 4096]"},
      {R"({"algo": "a2c", "horizon": 12})", "--horizon must be a multiple"},
      {R"({"hidden": [64, 0]})", "--hidden sizes must be >= 1"},
      {R"({"sync": true, "max_policy_lag": 2})",
       "--max_policy_lag must be 0 with --sync"},
      {R"({"horizon": 100, "segment_length": 30})",
       "--segment_length must divide --horizon"},
  };
  for (const auto& [json, message] : cases) {
    const absl::Status status = ResolveRunRequest(FromJson(json)).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << json;
    EXPECT_THAT(std::string(status.message()), HasSubstr(message)) << json;
  }
}

TEST(RunRequestTest, BadFilesAreNamed) {
  RunRequest missing;
  missing.config_file = "/no/such.json";
  EXPECT_THAT(std::string(ResolveRunRequest(missing).status().message()),
              HasSubstr("cannot read config file /no/such.json"));
  for (const auto& [json, key] :
       {std::pair<std::string, std::string>{R"({"rhoo": 1})", "rhoo"},
        {R"({"steps": "many"})", "steps"}}) {
    RunRequest request;
    request.config_file = WriteTemp("config.json", json);
    const absl::Status status = ResolveRunRequest(request).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << json;
    EXPECT_THAT(std::string(status.message()), HasSubstr(key)) << json;
  }
  RunRequest resume;
  resume.resume = "/no/such/run";
  EXPECT_THAT(std::string(ResolveRunRequest(resume).status().message()),
              HasSubstr("/no/such/run/config.json"));
}

TEST(RunRequestTest, ResumingRefusesChangesAndOtherDirectories) {
  RunRequest request = FromJson(R"({"rho": 0.9})");
  request.resume = "/some/run";
  EXPECT_THAT(std::string(ResolveRunRequest(request).status().message()),
              HasSubstr("drop --rho"));
  RunRequest both;
  both.resume = "/some/run";
  both.run_dir = "/other/run";
  EXPECT_THAT(std::string(ResolveRunRequest(both).status().message()),
              HasSubstr("drop --config and --run_dir"));
}

TEST(RunRequestTest, ARunThatCannotStartIsRefusedBeforeItStarts) {
  absl::StatusOr<ResolvedRun> unknown =
      ResolveRunRequest(FromJson(R"({"env": "Nope"})"));
  ASSERT_TRUE(unknown.ok()) << unknown.status();
  EXPECT_THAT(std::string(CheckRunCanStart(*unknown).message()),
              HasSubstr("unknown environment 'Nope'"));

  const std::string missing = TempPath("no_run");
  std::filesystem::remove_all(missing);
  RunRequest fresh;
  fresh.run_dir = missing;
  absl::StatusOr<ResolvedRun> run = ResolveRunRequest(fresh);
  ASSERT_TRUE(run.ok()) << run.status();
  EXPECT_TRUE(CheckRunCanStart(*run).ok());
  // Resuming a directory that holds no run.
  run->local.resume = true;
  EXPECT_FALSE(CheckRunCanStart(*run).ok());
}

}  // namespace
}  // namespace vantage
