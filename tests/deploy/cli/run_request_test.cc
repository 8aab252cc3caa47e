// What `vantage train` and `vantage learner` refuse before anything runs,
// checked in-process against the code the commands call (ResolveRunRequest,
// CheckRunCanStart); train_command_test checks that a refusal is one line
// on stderr and exit code 2.

#include "deploy/cli/run_request.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include "deploy/cli/run_flags.h"
#include "deploy/cli/train_command.h"
#include "deploy/run/run_config.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/algorithms/ppo/ppo_config.h"
#include "learner/run/run_directory.h"
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
      {R"({"mode": "cluster"})", "--mode: unknown mode 'cluster'"},
      {R"({"advantage": {"estimator": "median"}})",
       "unknown statistic 'median'"},
      {R"({"advantage": {"rho": 1.5}})", "rho must be in [0, 1]"},
      {R"({"training": {"steps": 0}})", "--steps must be >= 1"},
      {R"({"training": {"envs": 0}})", "--envs must be in [1, 4096]"},
      {R"({"a2c": {}, "training": {"horizon": 12}})",
       "--horizon is 12 but a2c's own settings make it 20"},
      {R"({"a2c": {"n": 0}})", "a2c.n must be >= 1 (--a2c_n)"},
      {R"({"ppo": {"epochs": 0}})", "ppo.epochs must be >= 1 (--ppo_epochs)"},
      {R"({"trpo": {"max_kl": 0}})", "trpo.max_kl must be > 0"},
      {R"({"training": {"hidden": [64, 0]}})", "--hidden sizes must be >= 1"},
      {R"({"distributed": {"sync": true, "max_policy_lag": 2}})",
       "--max_policy_lag must be 0 with --sync"},
      {R"({"training": {"horizon": 100, "segment_length": 30}})",
       "--segment_length must divide --horizon"},
      {R"({"exploration": {"ex2": {"kl_weight": -1}}})",
       "ex2.kl_weight must be in [0, 1e6), got -1 (--ex2_kl_weight)"},
      {R"({"exploration": {"ex2": {"encoder": "cnn"}}})",
       "ex2.encoder must be one of mlp, conv, got 'cnn'"},
      {R"({"mode": "local", "distributed": {"actors": 2}})",
       "--mode=local runs one strictly on-policy process: drop the "
       "distributed settings"},
  };
  for (const auto& [json, message] : cases) {
    const absl::Status status = ResolveRunRequest(FromJson(json)).status();
    EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument) << json;
    EXPECT_THAT(std::string(status.message()), HasSubstr(message)) << json;
  }
}

// --algo switches a config file's algorithm; other settings of another
// algorithm than the file's are refused instead of silently dropped.
TEST(RunRequestTest, TheAlgorithmIsChosenOnce) {
  RunRequest request;
  request.config_file =
      WriteTemp("a2c.json", R"({"a2c": {"n": 8}, "training": {"seed": 4}})");
  absl::StatusOr<ResolvedRun> file = ResolveRunRequest(request);
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_EQ(file->config.a2c().n(), 8);
  EXPECT_EQ(file->config.training().horizon(), 40);
  EXPECT_EQ(file->plan.learner.algorithm.name, "a2c");

  request.flags.mutable_ppo()->set_epochs(3);
  EXPECT_THAT(
      std::string(ResolveRunRequest(request).status().message()),
      HasSubstr("the flags set ppo settings but " + request.config_file +
                " holds a2c settings; add --algo=ppo to switch"));
  request.algo = "ppo";
  absl::StatusOr<ResolvedRun> switched = ResolveRunRequest(request);
  ASSERT_TRUE(switched.ok()) << switched.status();
  EXPECT_EQ(switched->config.ppo().epochs(), 3);
  EXPECT_EQ(switched->config.training().seed(), 4);
  EXPECT_EQ(switched->config.training().horizon(), 2048);
  EXPECT_EQ(switched->plan.learner.algorithm.Get<PpoConfig>().epochs, 3);
}

// --exploration=ex2 selects EX2 with its defaults, the --ex2_ flags
// select it too; --exploration=none drops a file's EX2.
TEST(RunRequestTest, ExplorationIsSelectedByFlagOrFile) {
  absl::StatusOr<RunRequest> request =
      RunRequestFromSettings({{"exploration", "ex2"}});
  ASSERT_TRUE(request.ok()) << request.status();
  absl::StatusOr<ResolvedRun> ex2 = ResolveRunRequest(*request);
  ASSERT_TRUE(ex2.ok()) << ex2.status();
  EXPECT_EQ(ex2->config.exploration().ex2().kl_weight(), 0.1);
  EXPECT_EQ(ex2->config.exploration().ex2().hidden_size(), 1);
  ASSERT_TRUE(ex2->plan.learner.exploration.ex2.has_value());
  EXPECT_EQ(ex2->plan.learner.exploration.ex2->train_iterations, 2000);

  request = RunRequestFromSettings(
      {{"ex2_kl_weight", "0.01"}, {"ex2_hidden", "16,16"}});
  ASSERT_TRUE(request.ok()) << request.status();
  absl::StatusOr<ResolvedRun> flags = ResolveRunRequest(*request);
  ASSERT_TRUE(flags.ok()) << flags.status();
  EXPECT_EQ(flags->plan.learner.exploration.ex2->kl_weight, 0.01);
  EXPECT_EQ(flags->plan.learner.exploration.ex2->hidden,
            (std::vector<int64_t>{16, 16}));

  // Without it: no section in config.json, no bonus.
  absl::StatusOr<ResolvedRun> plain = ResolveRunRequest(RunRequest());
  ASSERT_TRUE(plain.ok());
  EXPECT_FALSE(plain->config.has_exploration());
  EXPECT_FALSE(plain->plan.learner.exploration.enabled());

  RunRequest from_file;
  from_file.config_file = WriteTemp(
      "ex2.json", R"({"exploration": {"ex2": {"bonus_coeff": 0.01}}})");
  absl::StatusOr<ResolvedRun> file = ResolveRunRequest(from_file);
  ASSERT_TRUE(file.ok()) << file.status();
  EXPECT_EQ(file->plan.learner.exploration.ex2->bonus_coeff, 0.01);
  request = RunRequestFromSettings({{"exploration", "none"}});
  ASSERT_TRUE(request.ok());
  request->config_file = from_file.config_file;
  absl::StatusOr<ResolvedRun> dropped = ResolveRunRequest(*request);
  ASSERT_TRUE(dropped.ok()) << dropped.status();
  EXPECT_FALSE(dropped->config.has_exploration());

  EXPECT_THAT(
      std::string(
          RunRequestFromSettings({{"exploration", "vime"}}).status().message()),
      HasSubstr("--exploration: unknown exploration method 'vime'; "
                "available: none, ex2"));
  EXPECT_THAT(std::string(RunRequestFromSettings({{"exploration", "none"},
                                                  {"ex2_kl_weight", "0.1"}})
                              .status()
                              .message()),
              HasSubstr("--ex2_kl_weight is a setting of ex2; this run's "
                        "--exploration is none"));
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
  RunRequest request = FromJson(R"({"advantage": {"rho": 0.9}})");
  request.given_flags = {"rho"};
  request.resume = "/some/run";
  EXPECT_THAT(std::string(ResolveRunRequest(request).status().message()),
              HasSubstr("drop --rho"));
  RunRequest both;
  both.resume = "/some/run";
  both.run_dir = "/other/run";
  EXPECT_THAT(std::string(ResolveRunRequest(both).status().message()),
              HasSubstr("drop --config and --run_dir"));
}

// The actors serving a run are not the run (the learner's pool is
// elastic): a resumed run takes another --actors, --envs_per_actor or
// --actor_stall_timeout_s and keeps its batch; any other flag is refused,
// and --resume_if_exists recognises its run under another layout.
TEST(RunRequestTest, AResumedRunMayBeServedByOtherActors) {
  const std::string dir = FreshDirectory("served_by_others");
  RunRequest original =
      FromJson(R"({"training": {"steps": 4096}, "distributed": {"actors": 2, )"
               R"("envs_per_actor": 2}})");
  original.run_dir = dir;
  absl::StatusOr<ResolvedRun> first = ResolveRunRequest(original);
  ASSERT_TRUE(first.ok()) << first.status();
  ASSERT_TRUE(
      RunDirectory::Create(dir, first->plan.recording.config_json).ok());
  std::ofstream(dir + "/checkpoints/checkpoint-00000002.pt") << "x";

  RunRequest more =
      FromJson(R"({"distributed": {"actors": 5, "envs_per_actor": 1, )"
               R"("actor_stall_timeout_s": 20}})");
  more.given_flags = {"actors", "envs_per_actor", "actor_stall_timeout_s"};
  more.resume = dir;
  absl::StatusOr<ResolvedRun> resumed = ResolveRunRequest(more);
  ASSERT_TRUE(resumed.ok()) << resumed.status();
  EXPECT_EQ(resumed->config.distributed().actors(), 5);
  EXPECT_EQ(resumed->config.distributed().envs_per_actor(), 1);
  EXPECT_EQ(resumed->config.distributed().actor_stall_timeout_s(), 20);
  EXPECT_EQ(resumed->config.training().envs(), 4);  // the batch stays
  EXPECT_EQ(resumed->plan.learner.rollouts_per_batch, 4);

  RunRequest steps = FromJson(R"({"training": {"steps": 8192}})");
  steps.given_flags = {"actors", "steps"};
  steps.resume = dir;
  EXPECT_THAT(std::string(ResolveRunRequest(steps).status().message()),
              HasSubstr("(only --actors, --envs_per_actor and "
                        "--actor_stall_timeout_s may change); drop --steps"));

  RunRequest again =
      FromJson(R"({"training": {"steps": 4096, "envs": 4}, "distributed": )"
               R"({"actors": 3, "envs_per_actor": 1}})");
  again.run_dir = dir;
  again.resume_if_exists = true;
  absl::StatusOr<ResolvedRun> continued = ResolveRunRequest(again);
  ASSERT_TRUE(continued.ok()) << continued.status();
  EXPECT_TRUE(continued->plan.recording.resume);
  EXPECT_EQ(continued->config.distributed().actors(), 3);
}

TEST(RunRequestTest, ARunThatCannotStartIsRefusedBeforeItStarts) {
  absl::StatusOr<ResolvedRun> unknown =
      ResolveRunRequest(FromJson(R"({"training": {"env": "Nope"}})"));
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
  run->plan.recording.resume = true;
  EXPECT_FALSE(CheckRunCanStart(*run).ok());
}

// A scheduler repeats one command line (a requeued job, a restarted pod):
// --resume_if_exists starts the run, resumes it after a checkpoint, starts
// it over before one, and never touches a run made with other settings.
TEST(RunRequestTest, ResumeIfExistsStartsResumesOrStartsOver) {
  const std::string dir = FreshDirectory("resume_if_exists");
  RunRequest request = FromJson(R"({"training": {"steps": 4096}})");
  request.run_dir = dir;
  request.resume_if_exists = true;

  absl::StatusOr<ResolvedRun> fresh = ResolveRunRequest(request);
  ASSERT_TRUE(fresh.ok()) << fresh.status();
  EXPECT_FALSE(fresh->plan.recording.resume);
  EXPECT_FALSE(fresh->start_over);
  EXPECT_TRUE(CheckRunCanStart(*fresh).ok());

  // Killed before its first checkpoint: config.json and a row, no checkpoint.
  ASSERT_TRUE(
      RunDirectory::Create(dir, fresh->plan.recording.config_json).ok());
  absl::StatusOr<ResolvedRun> unstarted = ResolveRunRequest(request);
  ASSERT_TRUE(unstarted.ok()) << unstarted.status();
  EXPECT_TRUE(unstarted->start_over);
  EXPECT_FALSE(unstarted->plan.recording.resume);
  EXPECT_TRUE(CheckRunCanStart(*unstarted).ok());
  ASSERT_TRUE(PrepareRunDirectory(*unstarted).ok());
  EXPECT_FALSE(std::filesystem::exists(dir + "/config.json"));
  EXPECT_TRUE(RunDirectory::CheckFree(dir).ok());

  ASSERT_TRUE(
      RunDirectory::Create(dir, fresh->plan.recording.config_json).ok());
  std::ofstream(dir + "/checkpoints/checkpoint-00000002.pt") << "x";
  absl::StatusOr<ResolvedRun> resumed = ResolveRunRequest(request);
  ASSERT_TRUE(resumed.ok()) << resumed.status();
  EXPECT_TRUE(resumed->plan.recording.resume);
  EXPECT_FALSE(resumed->start_over);
  EXPECT_EQ(resumed->plan.recording.run_dir, dir);
  ASSERT_TRUE(PrepareRunDirectory(*resumed).ok());
  EXPECT_TRUE(std::filesystem::exists(dir + "/checkpoints"));

  RunRequest other = FromJson(R"({"training": {"steps": 8192}})");
  other.run_dir = dir;
  other.resume_if_exists = true;
  const absl::Status refused = ResolveRunRequest(other).status();
  EXPECT_EQ(refused.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(refused.message()),
              HasSubstr("holds a run made with other settings (modified: "
                        "training.steps: 4096 -> 8192)"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/config.json"));

  RunRequest no_dir = FromJson("{}");
  no_dir.resume_if_exists = true;
  EXPECT_THAT(std::string(ResolveRunRequest(no_dir).status().message()),
              HasSubstr("--resume_if_exists goes with --run_dir"));
}

}  // namespace
}  // namespace vantage
