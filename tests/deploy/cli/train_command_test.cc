#include <filesystem>
#include <string>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

TEST(TrainCommandTest, ShortRunWritesARunDirectory) {
  const std::string run = FreshDirectory("cli_run");
  const Outcome outcome = RunVantage(
      "train --mode=local --steps=512 --horizon=128 --envs=2 --seed=3 "
      "--checkpoint_every=1 --run_dir=" +
      run);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(outcome.out, HasSubstr("RESULT train env=InvertedPendulum "
                                     "algo=ppo estimator=maxabs rho=0.4 "
                                     "steps=512"));
  // Not a terminal: no progress line.
  EXPECT_THAT(outcome.out, Not(HasSubstr("ETA")));
  const std::string progress = ReadFile(run + "/progress.csv");
  EXPECT_THAT(progress, HasSubstr("\n256,1,1,"));
  EXPECT_THAT(progress, HasSubstr("\n512,2,2,"));
  // The resolved config has every field of the run's sections.
  const std::string config = ReadFile(run + "/config.json");
  EXPECT_THAT(config, HasSubstr("\"ppo\": {"));
  EXPECT_THAT(config, HasSubstr("\"minibatches\": 32"));
  EXPECT_THAT(config, HasSubstr("\"gae_lambda\": 0.95"));
  EXPECT_THAT(config, HasSubstr("\"horizon\": \"128\""));
  EXPECT_TRUE(
      std::filesystem::exists(run + "/checkpoints/checkpoint-00000002.pt"));

  // The trained policy acts in `rollout`.
  const Outcome rollout =
      RunVantage("rollout --episodes=2 --checkpoint=" + run);
  ASSERT_EQ(rollout.exit_code, 0) << rollout.err;
  EXPECT_THAT(rollout.out, HasSubstr("version 2, deterministic actions"));
  EXPECT_THAT(rollout.out,
              HasSubstr("RESULT rollout env=InvertedPendulum obs_dim=4 "
                        "act_dim=1 episodes=2"));
  const Outcome wrong_env =
      RunVantage("rollout --env=Hopper --checkpoint=" + run);
  EXPECT_EQ(wrong_env.exit_code, 2);
  EXPECT_THAT(wrong_env.err, HasSubstr("trained on InvertedPendulum"));

  // The run's config.json is a valid --config; flags override it.
  const std::string again = FreshDirectory("cli_again");
  const Outcome rerun = RunVantage(
      "train --config=" + run + "/config.json --steps=256 --run_dir=" + again);
  ASSERT_EQ(rerun.exit_code, 0) << rerun.err;
  EXPECT_THAT(rerun.out, HasSubstr("steps=256"));
  EXPECT_THAT(ReadFile(again + "/config.json"), HasSubstr("\"seed\": \"3\""));
}

// A policy trained on stacked frames acts on stacked frames.
TEST(TrainCommandTest, AStackedFramesPolicyRollsOut) {
  const std::string run = FreshDirectory("cli_stacked");
  const Outcome outcome = RunVantage(
      "train --mode=local --env=MinAtarBreakout --algo=a2c --steps=400 "
      "--envs=2 --frame_stack=4 --run_dir=" +
      run);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(ReadFile(run + "/config.json"),
              HasSubstr("\"frame_stack\": \"4\""));
  const Outcome rollout =
      RunVantage("rollout --episodes=1 --checkpoint=" + run);
  ASSERT_EQ(rollout.exit_code, 0) << rollout.err;
  EXPECT_THAT(rollout.out,
              HasSubstr("RESULT rollout env=MinAtarBreakout obs_dim=1600"));
  EXPECT_EQ(RunVantage("train --mode=local --env=MinAtarBreakout "
                       "--frame_stack=17 --steps=400")
                .exit_code,
            2);
}

// Networks that cannot be built for the environment are a usage error
// before the run directory exists; a shared torso trains.
TEST(TrainCommandTest, NetworksAreCheckedBeforeTheRunDirectoryExists) {
  const std::string run = FreshDirectory("cli_shared_torso");
  const Outcome vectors = RunVantage(
      "train --mode=local --env=InvertedPendulum --shared_torso --steps=400 "
      "--run_dir=" +
      run);
  EXPECT_EQ(vectors.exit_code, 2);
  EXPECT_THAT(vectors.err, HasSubstr("a shared torso needs a convolutional "
                                     "one, but 'InvertedPendulum' gets the "
                                     "mlp torso"));
  EXPECT_FALSE(std::filesystem::exists(run + "/config.json"));
  const Outcome shared = RunVantage(
      "train --mode=local --env=MinAtarBreakout --algo=a2c "
      "--shared_torso --steps=600 --run_dir=" +
      run);
  ASSERT_EQ(shared.exit_code, 0) << shared.err;
  EXPECT_THAT(ReadFile(run + "/config.json"),
              HasSubstr("\"shared_torso\": true"));
}

TEST(TrainCommandTest, ResumeContinuesTheRun) {
  const std::string run = FreshDirectory("cli_resume");
  const std::string config = WriteTemp("resume.json",
                                       R"({"mode": "local", "trpo": {},
                    "training": {"steps": 768, "horizon": 128, "envs": 2}})");
  ASSERT_EQ(RunVantage("train --checkpoint_every=1 --config=" + config +
                       " --run_dir=" + run)
                .exit_code,
            0);
  // Changing a finished run's config on resume is refused...
  const Outcome changed = RunVantage("train --rho=0.9 --resume=" + run);
  EXPECT_EQ(changed.exit_code, 2);
  EXPECT_THAT(changed.err, HasSubstr("drop --rho"));
  // ... and resuming a finished run has nothing left to do.
  const Outcome resumed = RunVantage("train --resume=" + run);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_THAT(resumed.out, HasSubstr("resuming InvertedPendulum with trpo"));
}

TEST(TrainCommandTest, BadFlagsAreOneLineErrors) {
  const std::string taken = FreshDirectory("cli_taken");
  // With no --mode the main job runs: a learner and two actor processes.
  const Outcome defaults =
      RunVantage("train --steps=10 --horizon=10 --run_dir=" + taken);
  ASSERT_EQ(defaults.exit_code, 0) << defaults.err;
  EXPECT_THAT(defaults.out, HasSubstr("1 learner + 2 actors x 1 envs"));
  EXPECT_THAT(ReadFile(taken + "/config.json"),
              HasSubstr("\"mode\": \"distributed\""));
  // One case of each kind (the config rules themselves are checked
  // in-process, run_request_test): a bad value, a bad list entry, a missing
  // file, an unknown environment, a taken run directory, a missing run.
  const std::pair<std::string, std::string> cases[] = {
      {"train --algo=sac",
       "--algo: unknown algorithm 'sac'; available: a2c, ppo, trpo"},
      {"train --ensemble=1,x", "--ensemble entry 'x'"},
      {"train --env=Nope --steps=10", "unknown environment 'Nope'"},
      {"train --config=/no/such.json", "cannot read config file /no/such.json"},
      {"train --resume=/no/such/run", "/no/such/run/config.json"},
      {"train --steps=10 --run_dir=" + taken, "already holds a run"},
      {"rollout --checkpoint=/no/such/run", "no checkpoint file"},
      {"train --eval_every=5 --eval_episodes=0",
       "--eval_episodes must be in [1, 100000]"},
  };
  for (const auto& [args, message] : cases) {
    const Outcome outcome = RunVantage(args);
    EXPECT_EQ(outcome.exit_code, 2) << args;
    EXPECT_THAT(outcome.err, HasSubstr(message)) << args;
    EXPECT_EQ(std::count(outcome.err.begin(), outcome.err.end(), '\n'), 1)
        << args << ": " << outcome.err;
  }
}

}  // namespace
}  // namespace vantage
