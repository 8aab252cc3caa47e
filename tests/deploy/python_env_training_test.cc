// A Python environment trains as every task does, with the same commands:
// PPO learns the test tree's CartPole locally and distributed (and with a
// recurrent core, a memory task the test tree writes in Python), a run
// resumes (exactly with get_state, restarting episodes without), and a
// factory that cannot be imported is a usage error before anything starts.
// PYTHONPATH holds tests/python_envs.

#include <ATen/Parallel.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "deploy/run/local_training.h"
#include "deploy/run/run_config.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"
#include "tests/fakes/local_plan.h"
#include "tests/fakes/run_files.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

std::string FreshDirectory(const std::string& name) {
  const std::string path = std::string(::testing::TempDir()) + "/" + name;
  std::filesystem::remove_all(path);
  return path;
}

// The best mean return (of the last 100 episodes) in a run's progress.csv.
double BestMeanReturn(const std::string& run_dir) {
  std::ifstream file(run_dir + "/progress.csv");
  std::string line;
  std::getline(file, line);
  const std::vector<std::string> names = absl::StrSplit(line, ',');
  const size_t column =
      std::find(names.begin(), names.end(), "mean_return") - names.begin();
  double best = 0.0;
  while (std::getline(file, line)) {
    const std::vector<std::string> values = absl::StrSplit(line, ',');
    if (column < values.size() && !values[column].empty()) {
      best = std::max(best, std::stod(values[column]));
    }
  }
  return best;
}

// configs/python_cartpole_ppo.json: RL Zoo's PPO settings for CartPole
// (8 envs x 32 steps, 20 epochs of one minibatch, lr 1e-3, gamma 0.98,
// lambda 0.8, no entropy bonus) with plain GAE, 100k steps. A uniformly
// random policy's mean return is about 22; the cap is 500.
constexpr char kCartPole[] = "--config=configs/python_cartpole_ppo.json";

// A local run repeats bit for bit only where OpenBLAS runs the same
// kernels, and one seed's curve moves with them: measured 2026-12-06 on an
// AVX-512 EPYC, seed 1 reached 500 with the Haswell and Zen kernels but
// 430 with SkylakeX's, seed 4 missed 450 with all three (329, 188, 329),
// seeds 0, 2, 3 and 5 reached 497-500 with each. So the bar is the median
// of seeds 0-2 (500 under every kernel set measured), which one unlucky
// curve cannot sink and no run without learning reaches.
TEST(PythonEnvTrainingTest, PpoLearnsCartPoleLocally) {
  std::vector<double> best;
  for (int seed : {0, 1, 2}) {
    const std::string run =
        FreshDirectory(absl::StrCat("python_cartpole_local_", seed));
    const Outcome outcome =
        RunVantage(absl::StrCat("train --mode=local ", kCartPole,
                                " --seed=", seed, " --run_dir=", run));
    ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
    EXPECT_THAT(outcome.out, HasSubstr("env=python:cartpole:make"));
    best.push_back(BestMeanReturn(run));
    std::printf("cartpole seed %d: best mean return %.1f\n", seed, best.back());
  }
  std::sort(best.begin(), best.end());
  EXPECT_GE(best[1], 450.0);
}

// Distributed runs reached 500 with seeds 0-2 under the Haswell and
// SkylakeX kernels alike on an idle machine (2026-12-06), but seed 1 ended
// at 430 once under the full suite's load, where actors and learner time
// share two cores differently: the bar is the median of seeds 0-2, as
// locally.
TEST(PythonEnvTrainingTest, PpoLearnsCartPoleDistributed) {
  std::vector<double> best;
  for (int seed : {0, 1, 2}) {
    const std::string run =
        FreshDirectory(absl::StrCat("python_cartpole_distributed_", seed));
    const Outcome outcome = RunVantage(
        absl::StrCat("train ", kCartPole, " --seed=", seed,
                     " --actors=2 --envs_per_actor=4 --run_dir=", run));
    ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
    best.push_back(BestMeanReturn(run));
    std::printf("distributed cartpole seed %d: best mean return %.1f\n", seed,
                best.back());
  }
  std::sort(best.begin(), best.end());
  EXPECT_GE(best[1], 450.0);
}

// A distributed run evaluates a Python environment on the learner's own
// thread (its interpreter used off the main thread), and its last row
// holds the final version's evaluation.
TEST(PythonEnvTrainingTest, ALearnerEvaluatesAPythonEnvBesideTraining) {
  const std::string run = FreshDirectory("python_evaluated");
  const Outcome outcome = RunVantage(
      "train --env=python:cartpole:make --steps=20480 --eval_every=2 "
      "--eval_episodes=3 --run_dir=" +
      run);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const std::vector<std::string> rows = DeterministicProgress(run);
  ASSERT_EQ(rows.size(), 1u + 5);
  EXPECT_EQ(ProgressField(rows, 5, "eval_version"), "4");
  double mean = 0.0;
  ASSERT_TRUE(absl::SimpleAtod(ProgressField(rows, 5, "eval_return"), &mean));
  // CartPole's returns are episode lengths: at least 8 steps, at most 500.
  EXPECT_GE(mean, 8.0);
  EXPECT_LE(mean, 500.0);
}

// An environment whose step() now and then never returns: the hung actor's
// watchdog names the call and exits after --actor_stall_timeout_s, the
// launcher restarts it with environment seeds of its new life (so the same
// hang does not come back at the same step), and the run finishes.
// A user's partially observable environment, one frame at a time
// (tests/python_envs/cue_recall.py: a cue, 10 blank frames, then the frame
// that asks for it): a GRU core remembers the cue, the feed-forward policy
// stays at chance (0.25). Seed 1, 80k steps: 1.0 and 0.2 at the end
// (2026-12-06).
TEST(PythonEnvTrainingTest, AGruCoreRemembersWhatAPythonEnvShowedOnce) {
  double best[2] = {0.0, 0.0};
  for (int recurrent : {0, 1}) {
    const std::string run =
        FreshDirectory(absl::StrCat("python_cue_recall_", recurrent));
    const Outcome outcome = RunVantage(absl::StrCat(
        "train --mode=local --env=python:cue_recall:make --envs=8 "
        "--horizon=128 --ppo_minibatches=16 --steps=80000 --seed=1 ",
        recurrent ? "--core=gru --seq_len=16 " : "", "--run_dir=", run));
    ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
    best[recurrent] = BestMeanReturn(run);
  }
  EXPECT_GE(best[1], 0.9);
  EXPECT_LE(best[0], 0.5);
}

// The test tree's LitButtons (8 buttons, 2 lit, 16 presses; pressing any
// lit button scores 8 an episode, the best one 10.7) raises on an unlit
// press, so a run that finishes took no illegal action. Locally with the
// mask in the info (seed 1: best 9.5 in 32k steps); distributed with the
// mask as an observation key, evaluated on the learner (seed 1: 10.7 at
// version 4, 64k steps), the masks crossing gRPC.
TEST(PythonEnvTrainingTest, MaskedPythonEnvsTrainLocallyAndDistributed) {
  const std::string local = FreshDirectory("python_lit_buttons_local");
  Outcome outcome = RunVantage(absl::StrCat(
      "train --mode=local --env=python:lit_buttons:make --steps=32768 "
      "--seed=1 --run_dir=",
      local));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_GE(BestMeanReturn(local), 9.0);

  const std::string distributed =
      FreshDirectory("python_lit_buttons_distributed");
  outcome = RunVantage(absl::StrCat(
      "train --env=python:lit_buttons:make "
      "--env_kwargs='{\"mask_in\": \"observation\"}' --actors=2 "
      "--envs_per_actor=4 --steps=65536 --seed=1 --eval_every=4 --run_dir=",
      distributed));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const std::vector<std::string> rows = DeterministicProgress(distributed);
  ASSERT_EQ(rows.size(), 1u + 4);
  EXPECT_EQ(ProgressField(rows, 4, "eval_version"), "4");
  double evaluated = 0.0;
  ASSERT_TRUE(
      absl::SimpleAtod(ProgressField(rows, 4, "eval_return"), &evaluated));
  EXPECT_GE(evaluated, 8.8);
}

TEST(PythonEnvTrainingTest, AHungEnvironmentIsReplacedAndTheRunFinishes) {
  const std::string run = FreshDirectory("python_hangs");
  const Outcome outcome = RunVantage(
      "train --env=python:broken_envs:hangs_sometimes "
      "--env_kwargs='{\"p\": 0.0005}' --steps=8192 --actors=2 "
      "--envs_per_actor=2 --horizon=64 --actor_stall_timeout_s=2 --seed=3 "
      "--run_dir=" +
      run);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(outcome.err,
              HasSubstr("python:broken_envs:hangs_sometimes: step() has not "
                        "returned after 2s, beyond the run's actor stall "
                        "timeout (2s); exiting (code 75)"));
  EXPECT_THAT(outcome.err, HasSubstr("restarting it (life 2, env seed"));
  EXPECT_THAT(outcome.out, HasSubstr("RESULT train"));
}

TEST(PythonEnvTrainingTest, AFactoryThatCannotBeImportedIsAUsageError) {
  const Outcome outcome =
      RunVantage("train --env=python:no_such_module:make --steps=100");
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("python:no_such_module:make: the factory: "
                                     "ModuleNotFoundError: No module named "
                                     "'no_such_module'"));
  const Outcome kwargs = RunVantage(
      "train --env=python:cartpole:make --env_kwargs='[1]' --steps=100");
  EXPECT_EQ(kwargs.exit_code, 2);
}

// The same seed, the same episodes, through `vantage rollout`.
TEST(PythonEnvTrainingTest, RolloutsRepeatWithTheirSeed) {
  const std::string args =
      "rollout --env=python:pendulum:make --env_kwargs='{\"g\": 9.81}' "
      "--episodes=2 ";
  const Outcome first = RunVantage(args + "--seed=3");
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_THAT(first.out, HasSubstr("mean_length=200"));
  const auto digest = [](const std::string& out) {
    return out.substr(out.find("digest="));
  };
  EXPECT_EQ(digest(first.out), digest(RunVantage(args + "--seed=3").out));
  EXPECT_NE(digest(first.out), digest(RunVantage(args + "--seed=4").out));
}

// An env with render() is filmed: one frame after the reset and each step.
TEST(PythonEnvTrainingTest, AnEnvThatRendersIsFilmed) {
  const std::string video = FreshDirectory("python_video") + ".mp4";
  const Outcome outcome = RunVantage(
      "rollout --env=python:cartpole:make --episodes=1 --seed=1 --video=" +
      video);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(outcome.out, HasSubstr("mean_length=10.0"));
  EXPECT_THAT(outcome.out, HasSubstr("(11 frames, 480x320, 50 fps)"));
  EXPECT_GT(std::filesystem::file_size(video), 0u);
}

RunPlan SmallRun(const std::string& env, const std::string& run_dir,
                 const std::string& kwargs = "") {
  pb::RunConfig run;
  run.mutable_training()->set_env(env);
  if (!kwargs.empty()) run.mutable_training()->set_env_kwargs(kwargs);
  run.mutable_training()->set_envs(2);
  run.mutable_training()->set_horizon(64);
  run.mutable_training()->set_steps(6 * 2 * 64);
  run.mutable_ppo()->set_epochs(2);
  run.mutable_recording()->set_checkpoint_every(2);
  RunPlan plan = LocalPlan(run);
  plan.recording.run_dir = run_dir;
  return plan;
}

void Train(const RunPlan& plan, int stop_after = 1000) {
  const absl::Status status =
      RunLocalTraining(plan, [&](const ProgressRow& row) {
        return row.stats.policy_version < stop_after;
      });
  ASSERT_TRUE(status.ok()) << status;
}

// CartPole saves its state (get_state): a run stopped after update 5 and
// resumed from update 4's checkpoint equals the uninterrupted one. Pendulum
// cannot: its resumed run restarts the episodes under way and completes.
TEST(PythonEnvTrainingTest, ARunResumesExactlyOrWithItsEpisodesRestarted) {
  at::set_num_threads(1);
  const std::string whole = FreshDirectory("python_whole");
  const std::string broken = FreshDirectory("python_broken");
  Train(SmallRun("python:cartpole:make", whole));
  Train(SmallRun("python:cartpole:make", broken), /*stop_after=*/5);
  RunPlan resume = SmallRun("python:cartpole:make", broken);
  resume.recording.resume = true;
  Train(resume);
  EXPECT_EQ(DeterministicProgress(broken), DeterministicProgress(whole));

  const std::string pendulum = FreshDirectory("python_pendulum");
  Train(SmallRun("python:pendulum:make", pendulum), /*stop_after=*/5);
  RunPlan again = SmallRun("python:pendulum:make", pendulum);
  again.recording.resume = true;
  Train(again);
  EXPECT_EQ(DeterministicProgress(pendulum).size(), 1u + 6);
}

// MultiDiscrete and MultiBinary actions, masks in the info or as an
// observation key, and a Dict observation resume exactly too (their envs
// have get_state).
TEST(PythonEnvTrainingTest, StructuredAndMaskedActionsResumeExactly) {
  at::set_num_threads(1);
  const std::vector<std::pair<std::string, std::string>> envs = {
      {"python:match_targets:make", ""},
      {"python:match_targets:make", R"({"binary": 5})"},
      {"python:lit_buttons:make", ""},
      {"python:lit_buttons:make", R"({"mask_in": "observation"})"},
      {"python:lit_pixel:make", ""},
  };
  for (size_t i = 0; i < envs.size(); ++i) {
    const auto& [env, kwargs] = envs[i];
    const std::string whole = FreshDirectory(absl::StrCat("whole_", i));
    const std::string broken = FreshDirectory(absl::StrCat("broken_", i));
    Train(SmallRun(env, whole, kwargs));
    Train(SmallRun(env, broken, kwargs), /*stop_after=*/5);
    RunPlan resume = SmallRun(env, broken, kwargs);
    resume.recording.resume = true;
    Train(resume);
    EXPECT_EQ(DeterministicProgress(broken), DeterministicProgress(whole))
        << env << " " << kwargs;
  }
}

// MatchTargets (tests/python_envs/match_targets.py): one target per action
// value each step, the reward the fraction matched, 16 steps. Uniformly
// random actions score 4.2 (MultiDiscrete 3x4x5) and 8 (MultiBinary 6);
// reading the targets scores 16. Seed 1, 64k steps, PPO's defaults: 13.1
// and 13.2 (2026-12-06).
TEST(PythonEnvTrainingTest, PpoLearnsMultiDiscreteAndMultiBinaryActions) {
  for (const std::string kwargs : {"{}", R"({"binary": 6})"}) {
    const std::string run =
        FreshDirectory(absl::StrCat("python_match_targets_", kwargs.size()));
    const Outcome outcome = RunVantage(absl::StrCat(
        "train --mode=local --env=python:match_targets:make --env_kwargs='",
        kwargs, "' --steps=65536 --seed=1 --run_dir=", run));
    ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
    EXPECT_GE(BestMeanReturn(run), 11.5) << kwargs;
  }
}

// LitPixel (tests/python_envs/lit_pixel.py): a Dict of a 5x5 camera image
// with one lit pixel and a 2-value "mirror" vector; the answer is the lit
// column, mirrored when the vector says so, so a policy needs both (the
// camera through its own convolutional torso, the vector normalised, both
// into the MLP). A uniformly random policy scores 1.6 of 8. Seed 1, 48k
// steps: 7.75, as a Dict and as a Tuple (2026-12-06).
TEST(PythonEnvTrainingTest, PpoLearnsADictOfAnImageAndAVector) {
  const std::string run = FreshDirectory("python_lit_pixel");
  const Outcome outcome = RunVantage(
      "train --mode=local --env=python:lit_pixel:make --steps=49152 --seed=1 "
      "--run_dir=" +
      run);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(outcome.err, HasSubstr("acting on LibTorch"));
  EXPECT_GE(BestMeanReturn(run), 6.0);
}

}  // namespace
}  // namespace vantage
