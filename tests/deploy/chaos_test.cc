// A distributed run under fire: a driver SIGKILLs random actors 20 times
// and the learner twice, at random moments, while `vantage train`
// supervises them. The run must complete with one progress row per policy
// version and no NaN, and every checkpoint it leaves must load.

#include <signal.h>

#include <chrono>
#include <filesystem>
#include <random>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"
#include "tests/fakes/learner_process.h"
#include "tests/fakes/run_files.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

int CountOf(const std::string& text, const std::string& what) {
  int count = 0;
  for (size_t at = text.find(what); at != std::string::npos;
       at = text.find(what, at + 1)) {
    ++count;
  }
  return count;
}

TEST(ChaosTest, TheRunSurvivesKilledActorsAndLearners) {
  const std::string run = FreshDirectory("chaos");
  const std::string err = TempPath("train.err");
  const int train = StartVantage(
      "train --actors=2 --envs_per_actor=1 --steps=120000 --horizon=256 "
      "--checkpoint_every=1 --seed=7 --run_dir=" +
          run,
      TempPath("train.out"), err);
  // A fixed schedule, so that a failure can be rerun.
  std::mt19937 random(20261201);
  std::uniform_int_distribution<int> pause_ms(150, 700);
  std::vector<bool> learner_kill(22, false);
  learner_kill[7] = learner_kill[16] = true;
  int actor_kills = 0;
  int learner_kills = 0;
  for (size_t i = 0; i < learner_kill.size(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms(random)));
    // Strike only while training is under way: a first version exists and
    // every process is up (a restarted one may still be starting).
    for (int wait = 0; wait < 600; ++wait) {
      if (DeterministicProgress(run).size() >= 2 &&
          ChildrenRunning(train, " learner ").size() == 1 &&
          ChildrenRunning(train, " actor ").size() == 2) {
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (learner_kill[i]) {
      const std::vector<int> learners = ChildrenRunning(train, " learner ");
      ASSERT_EQ(learners.size(), 1u) << ReadFile(err);
      kill(learners[0], SIGKILL);
      ++learner_kills;
    } else {
      const std::vector<int> actors = ChildrenRunning(train, " actor ");
      ASSERT_FALSE(actors.empty()) << ReadFile(err);
      kill(actors[random() % actors.size()], SIGKILL);
      ++actor_kills;
    }
  }
  EXPECT_EQ(WaitVantage(train, 600), 0) << ReadFile(err);
  const std::string log = ReadFile(err);
  EXPECT_EQ(actor_kills, 20);
  EXPECT_EQ(learner_kills, 2);
  EXPECT_EQ(CountOf(log, "the learner ended (signal 9); resuming it"), 2)
      << log;
  EXPECT_GE(CountOf(log, "ended (signal 9); restarting it"), 20) << log;
  // Each restart is a new life of its actor, with environment seeds no
  // earlier life had (a crash its episodes caused would repeat otherwise).
  std::set<std::string> seeds;
  int lives = 0;
  for (absl::string_view line : absl::StrSplit(log, '\n')) {
    const size_t at = line.find(", env seed ");
    if (line.find("restarting it (life ") == absl::string_view::npos ||
        at == absl::string_view::npos) {
      continue;
    }
    seeds.insert(std::string(line.substr(at)));
    ++lives;
  }
  EXPECT_GE(lives, 20) << log;
  EXPECT_EQ(static_cast<int>(seeds.size()), lives) << log;

  const std::vector<std::string> rows = DeterministicProgress(run);
  // 120000 steps of batches of at least 2 x 256-step rollouts: at most 235
  // updates (the last batch passes the step count). A batch is larger
  // while one actor stands in for a killed one (its grant grows) and the
  // restarted one joins it, so a few updates fewer, never a gap.
  ASSERT_LE(rows.size(), 1u + 235);
  ASSERT_GE(rows.size(), 1u + 200);
  int64_t last_steps = 0;
  for (size_t v = 1; v < rows.size(); ++v) {
    const std::vector<std::string> fields = absl::StrSplit(rows[v], ',');
    ASSERT_GE(fields.size(), 3u);
    last_steps = std::stoll(fields[0]);
    EXPECT_EQ(fields[1], std::to_string(v)) << rows[v];
    EXPECT_EQ(fields[2], std::to_string(v)) << rows[v];
    EXPECT_THAT(rows[v], ::testing::Not(HasSubstr("nan"))) << rows[v];
    EXPECT_THAT(rows[v], ::testing::Not(HasSubstr("inf"))) << rows[v];
  }
  EXPECT_GE(last_steps, 120000);
  int checkpoints = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(run + "/checkpoints")) {
    const Outcome rollout = RunVantage("rollout --episodes=1 --checkpoint=" +
                                       entry.path().string());
    EXPECT_EQ(rollout.exit_code, 0) << entry.path() << "\n" << rollout.err;
    ++checkpoints;
  }
  EXPECT_GE(checkpoints, 1);
  EXPECT_TRUE(ChildrenRunning(train, "vantage").empty());
}

}  // namespace
}  // namespace vantage
