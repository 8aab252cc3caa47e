// The learner and actors as separate processes over loopback gRPC.

#include <signal.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "gmock/gmock.h"
#include "google/protobuf/struct.pb.h"
#include "google/protobuf/util/json_util.h"
#include "gtest/gtest.h"
#include "learner/run/progress_columns.h"
#include "tests/deploy/cli/run_vantage.h"
#include "tests/fakes/http_get.h"
#include "tests/fakes/learner_process.h"
#include "tests/fakes/run_files.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

constexpr char kRun[] = "--steps=3072 --horizon=256 --envs=2 --seed=5";

// A --sync run with one actor trains on exactly the data of local mode and
// repeats its progress.csv (wall clock aside); with EX2 too, whose model
// fits on the learner from update 2 on, and with stacked frames, which the
// actor learns from the learner's run config.
void ExpectSyncWithOneActorReproducesLocalMode(const std::string& tag,
                                               const std::string& extra) {
  const bool ex2 = tag == "ex2";
  const std::string local = FreshDirectory("local" + tag);
  const std::string remote = FreshDirectory("remote" + tag);
  const std::string run = std::string(kRun) + extra;
  ASSERT_EQ(
      RunVantage("train --mode=local " + run + " --run_dir=" + local).exit_code,
      0);
  const Learner learner = StartLearner(run + " --run_dir=" + remote);
  const std::string actor_err = TempPath("actor.err");
  const int actor =
      StartVantage("actor --learner=127.0.0.1:" + learner.port +
                       " --env=InvertedPendulum --envs=2 --seed=5",
                   TempPath("actor.out"), actor_err);
  EXPECT_EQ(WaitVantage(learner.pid, 120), 0) << ReadFile(learner.err);
  kill(actor, SIGTERM);
  EXPECT_EQ(WaitVantage(actor, 20), 0);
  // A --seed given is the environments' seed, as in local mode.
  EXPECT_THAT(ReadFile(actor_err), HasSubstr(", env seed 5\n"));
  EXPECT_THAT(ReadFile(learner.out), HasSubstr("RESULT train"));
  const std::vector<std::string> expected = DeterministicProgress(local);
  ASSERT_EQ(expected.size(), 1u + 6);
  EXPECT_EQ(DeterministicProgress(remote), expected);
  if (ex2) {
    // The last row's exploration_loss is that of a fit.
    EXPECT_NE(ProgressField(expected, 6, "exploration_loss"), "")
        << expected.back();
  }
}

TEST(DistributedTest, SyncWithOneActorReproducesLocalMode) {
  ExpectSyncWithOneActorReproducesLocalMode("", "");
}

TEST(DistributedTest, SyncWithOneActorReproducesLocalModeWithStackedFrames) {
  ExpectSyncWithOneActorReproducesLocalMode("stacked", " --frame_stack=3");
}

// A recurrent policy's state travels with each segment and its chunks
// start from the learner's own pass: the same numbers either way.
TEST(DistributedTest, SyncWithOneActorReproducesLocalModeWithAGruCore) {
  ExpectSyncWithOneActorReproducesLocalMode(
      "gru", " --core=gru --core_size=16 --seq_len=16");
}

TEST(DistributedTest, SyncWithOneActorReproducesLocalModeWithEx2) {
  ExpectSyncWithOneActorReproducesLocalMode(
      "ex2",
      " --exploration=ex2 --ex2_replay_min=500 --ex2_first_train_iterations=50 "
      "--ex2_train_iterations=20 --ex2_bonus_coeff=0.1");
}

// Two actors of two envs each fill the learner's four-stream batches: no
// update can happen without both. Started with the same flags and no
// --seed (as a Deployment's pods are), their environments get different
// seeds from their registrations. When the run is complete the learner
// tells them so, and they exit 0 by themselves instead of reconnecting
// (forever, by default) to a learner that is gone.
TEST(DistributedTest, TwoActorsFeedOneLearner) {
  const std::string run = FreshDirectory("two");
  const Learner learner = StartLearner(
      "--steps=4096 --horizon=256 --envs=4 --seed=1 --run_dir=" + run);
  std::vector<int> actors;
  std::vector<std::string> logs;
  for (int i = 0; i < 2; ++i) {
    logs.push_back(TempPath("a.err"));
    actors.push_back(StartVantage("actor --learner=127.0.0.1:" + learner.port +
                                      " --env=InvertedPendulum --envs=2",
                                  TempPath("a.out"), logs.back()));
  }
  EXPECT_EQ(WaitVantage(learner.pid, 120), 0) << ReadFile(learner.err);
  std::set<std::string> seeds;
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(WaitVantage(actors[i], 20), 0) << ReadFile(logs[i]);
    const std::string log = ReadFile(logs[i]);
    EXPECT_THAT(log, HasSubstr("the run is over: every step is done; "
                               "exiting"));
    EXPECT_THAT(log, Not(HasSubstr("reconnecting")));
    const size_t at = log.find(", env seed ");
    ASSERT_NE(at, std::string::npos) << log;
    seeds.insert(log.substr(at, log.find('\n', at) - at));
  }
  EXPECT_EQ(seeds.size(), 2u) << *seeds.begin();
  const std::vector<std::string> rows = DeterministicProgress(run);
  ASSERT_EQ(rows.size(), 1u + 4);
  EXPECT_THAT(rows[4], ::testing::StartsWith("4096,4,4,"));
}

// The main job: `vantage train --actors=2` supervises its processes; an
// actor killed with SIGKILL mid-run is restarted (and logged), the learner
// keeps training and the run completes.
// The run's scrape targets (prometheus_targets.json): role and actor label
// -> address, for every process listed.
std::map<std::string, std::string> ScrapeTargets(const std::string& run) {
  google::protobuf::ListValue list;
  std::map<std::string, std::string> targets;
  if (!google::protobuf::util::JsonStringToMessage(
           ReadFile(run + "/prometheus_targets.json"), &list)
           .ok()) {
    return targets;
  }
  for (const google::protobuf::Value& group : list.values()) {
    const auto& fields = group.struct_value().fields();
    const auto& labels = fields.at("labels").struct_value().fields();
    std::string who = labels.at("role").string_value();
    if (labels.count("actor") > 0) {
      absl::StrAppend(&who, "-", labels.at("actor").string_value());
    }
    EXPECT_EQ(labels.at("run").string_value(),
              std::filesystem::absolute(run).lexically_normal().string());
    EXPECT_EQ(labels.at("env").string_value(), "InvertedPendulum");
    targets[who] = fields.at("targets").list_value().values(0).string_value();
  }
  return targets;
}

// With --metrics the run's scrape targets follow its processes: an actor
// restarted on a free port is listed there, and a finished run lists none.
TEST(DistributedTest, TrainRestartsAKilledActor) {
  const std::string run = FreshDirectory("supervised");
  const std::string err = TempPath("train.err");
  const int train = StartVantage(
      "train --actors=2 --envs_per_actor=1 --steps=49152 --horizon=512 "
      "--seed=3 --metrics=0 --run_dir=" +
          run,
      TempPath("train.out"), err);
  // Wait for the first update, then kill one actor at once: under a loaded
  // machine the metrics checks take seconds, and the run must still have
  // updates left that need the restarted actor (a sync batch takes one
  // horizon of each).
  for (int i = 0; i < 1200 && DeterministicProgress(run).size() < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GE(DeterministicProgress(run).size(), 2u) << ReadFile(err);
  std::map<std::string, std::string> targets;
  for (int i = 0; i < 200 && targets.size() < 3; ++i) {
    targets = ScrapeTargets(run);
    if (targets.size() < 3) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  ASSERT_EQ(targets.size(), 3u) << ReadFile(run + "/prometheus_targets.json");
  const std::vector<int> actors = ChildrenRunning(train, " actor ");
  ASSERT_EQ(actors.size(), 2u);
  const std::string killed =
      ReadFile("/proc/" + std::to_string(actors[0]) + "/cmdline")
                  .find("actor-1") != std::string::npos
          ? "actor-1"
          : "actor-0";
  kill(actors[0], SIGKILL);
  for (const auto& [who, address] : targets) {
    if (who == killed) continue;
    const std::string port = address.substr(address.rfind(':') + 1);
    int number = 0;
    ASSERT_TRUE(absl::SimpleAtoi(port, &number)) << address;
    absl::StatusOr<std::string> text = HttpGet(number, "/metrics");
    ASSERT_TRUE(text.ok()) << who << ": " << text.status();
    EXPECT_THAT(*text, HasSubstr(who == "learner" ? "vantage_learner_"
                                                  : "vantage_actor_"));
  }
  std::map<std::string, std::string> after = targets;
  for (int i = 0;
       i < 600 && after[killed] == targets[killed] && kill(train, 0) == 0;
       ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    after = ScrapeTargets(run);
  }
  EXPECT_NE(after[killed], targets[killed]) << killed;
  EXPECT_EQ(WaitVantage(train, 180), 0) << ReadFile(err);
  EXPECT_THAT(ReadFile(run + "/prometheus_targets.json"),
              ::testing::MatchesRegex("\\[\\s*\\]\\s*"));
  EXPECT_THAT(ReadFile(err), HasSubstr("ended (signal 9); restarting it"));
  // Under a new id: its streams are new ones, never stitched onto the
  // killed actor's.
  EXPECT_THAT(ReadFile(err), HasSubstr("registered as actor 2,"));
  const std::vector<std::string> rows = DeterministicProgress(run);
  ASSERT_EQ(rows.size(), 1u + 48);
  EXPECT_THAT(rows[48], ::testing::StartsWith("49152,48,48,"));
  // No process of the run is left behind.
  EXPECT_TRUE(ChildrenRunning(train, "vantage").empty());
}

// Evaluations in a distributed run go on beside the learner (a low-priority
// thread of its process): their results land in later rows, versions a
// newer one overtook are skipped, and the run's last row waits for the
// final version's. checkpoints/best.pt is the best evaluated version's and
// plays as a trained policy; nothing is left held.
TEST(DistributedTest, EvaluationsRunBesideTheLearnerAndKeepTheBest) {
  const std::string run = FreshDirectory("evaluated");
  const Outcome trained = RunVantage(
      "train --actors=2 --envs_per_actor=1 --steps=16384 --horizon=512 "
      "--eval_every=4 --eval_episodes=2 --seed=2 --metrics=0 --run_dir=" +
      run);
  ASSERT_EQ(trained.exit_code, 0) << trained.err;
  const std::vector<std::string> rows = DeterministicProgress(run);
  ASSERT_EQ(rows.size(), 1u + 16);
  int64_t previous = 0;
  for (size_t row = 1; row < rows.size(); ++row) {
    const std::string evaluated = ProgressField(rows, row, "eval_version");
    if (evaluated.empty()) continue;
    int64_t version = 0;
    ASSERT_TRUE(absl::SimpleAtoi(evaluated, &version)) << rows[row];
    EXPECT_EQ(version % 4, 0) << rows[row];
    EXPECT_GT(version, previous) << rows[row];
    EXPECT_LE(version, static_cast<int64_t>(row)) << rows[row];
    EXPECT_NE(ProgressField(rows, row, "eval_return"), "") << rows[row];
    previous = version;
  }
  EXPECT_EQ(previous, 16);
  EXPECT_THAT(ReadFile(run + "/checkpoints/best.json"),
              ::testing::MatchesRegex("\\{\"version\": (4|8|12|16), .*\n"));
  const Outcome played = RunVantage("rollout --checkpoint=" + run +
                                    "/checkpoints/best.pt --episodes=1");
  EXPECT_EQ(played.exit_code, 0) << played.err;
  EXPECT_THAT(played.out, HasSubstr("RESULT rollout"));
  for (const auto& entry :
       std::filesystem::directory_iterator(run + "/checkpoints")) {
    EXPECT_THAT(entry.path().filename().string(),
                ::testing::Not(::testing::StartsWith("evaluating-")));
  }
}

// The second fault: the learner is killed with SIGKILL mid-run. The
// launcher restarts it from the run's last checkpoint on the same port, the
// actor (still holding its environments) reconnects under a new id and
// gets that checkpoint's policy, and the run completes with one progress
// row per version: the rows written after the checkpoint were dropped and
// written again by the resumed learner.
TEST(DistributedTest, AKilledLearnerResumesFromItsLastCheckpoint) {
  const std::string run = FreshDirectory("learner_killed");
  const std::string err = TempPath("train.err");
  const int train = StartVantage(
      "train --actors=1 --envs_per_actor=2 --steps=8192 --horizon=512 "
      "--checkpoint_every=2 --seed=4 --run_dir=" +
          run,
      TempPath("train.out"), err);
  for (int i = 0; i < 1200 && DeterministicProgress(run).size() < 1 + 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GE(DeterministicProgress(run).size(), 1u + 3) << ReadFile(err);
  const std::vector<int> learners = ChildrenRunning(train, " learner ");
  ASSERT_EQ(learners.size(), 1u);
  kill(learners[0], SIGKILL);
  EXPECT_EQ(WaitVantage(train, 240), 0) << ReadFile(err);
  const std::string log = ReadFile(err);
  EXPECT_THAT(log, HasSubstr("the learner ended (signal 9); resuming it"));
  // The version it resumed from is one that had a checkpoint (every 2).
  const std::string marker = "from policy version ";
  const size_t at = log.find(marker);
  ASSERT_NE(at, std::string::npos) << log;
  int version = 0;
  ASSERT_TRUE(absl::SimpleAtoi(
      log.substr(at + marker.size(),
                 log.find(' ', at + marker.size()) - at - marker.size()),
      &version))
      << log;
  EXPECT_GE(version, 2);
  EXPECT_EQ(version % 2, 0);
  // Actor ids are not reused across the restart, and the reconnected actor
  // acts with the checkpoint's policy.
  EXPECT_THAT(log, HasSubstr(absl::StrCat("registered as actor 1, policy "
                                          "version ",
                                          version, ", env seed ")));
  const std::vector<std::string> rows = DeterministicProgress(run);
  ASSERT_EQ(rows.size(), 1u + 8) << absl::StrJoin(rows, "\n");
  for (int v = 1; v <= 8; ++v) {
    EXPECT_THAT(rows[v], ::testing::StartsWith(
                             absl::StrCat(1024 * v, ",", v, ",", v, ",")));
  }
  EXPECT_TRUE(ChildrenRunning(train, "vantage").empty());
}

// A scheduler's preemption: SIGTERM to `vantage train` mid-run makes the
// learner checkpoint the update it is at (checkpoint_every alone would
// have written none yet), and `train --resume` finishes the run from there.
TEST(DistributedTest, AStoppedRunKeepsEveryUpdateAndResumes) {
  const std::string run = FreshDirectory("preempted");
  const std::string err = TempPath("train.err");
  const int train = StartVantage(
      "train --actors=1 --envs_per_actor=2 --steps=6144 --horizon=512 "
      "--checkpoint_every=100 --seed=6 --run_dir=" +
          run,
      TempPath("train.out"), err);
  for (int i = 0; i < 1200 && DeterministicProgress(run).size() < 1 + 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_GE(DeterministicProgress(run).size(), 1u + 2) << ReadFile(err);
  kill(train, SIGTERM);
  EXPECT_EQ(WaitVantage(train, 60), 0) << ReadFile(err);
  const size_t updates = DeterministicProgress(run).size() - 1;
  ASSERT_LT(updates, 6u);
  EXPECT_TRUE(std::filesystem::exists(
      absl::StrFormat("%s/checkpoints/checkpoint-%08d.pt", run, updates)))
      << ReadFile(err);

  const Outcome resumed = RunVantage("train --resume=" + run);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_THAT(resumed.err,
              HasSubstr(absl::StrCat("from policy version ", updates, " (")));
  const std::vector<std::string> rows = DeterministicProgress(run);
  ASSERT_EQ(rows.size(), 1u + 6) << absl::StrJoin(rows, "\n");
  for (int v = 1; v <= 6; ++v) {
    EXPECT_THAT(rows[v], ::testing::StartsWith(
                             absl::StrCat(1024 * v, ",", v, ",", v, ",")));
  }
}

// One column of a run's progress.csv, row by row.
std::vector<std::string> ProgressValues(const std::string& run_dir,
                                        const std::string& name) {
  std::ifstream file(run_dir + "/progress.csv");
  std::string line;
  std::getline(file, line);
  const std::vector<std::string> names = absl::StrSplit(line, ',');
  const size_t at = std::find(names.begin(), names.end(), name) - names.begin();
  std::vector<std::string> values;
  while (std::getline(file, line)) {
    const std::vector<std::string> fields = absl::StrSplit(line, ',');
    values.push_back(at < fields.size() ? fields[at] : "?");
  }
  return values;
}

std::string ActorCommand(const Learner& learner, int envs) {
  return absl::StrCat("actor --learner=127.0.0.1:", learner.port,
                      " --env=InvertedPendulum --envs=", envs);
}

// The batch is the run's, not the actors': a sync learner planned for two
// actors of two envs, served by one, grants that one's slots two horizons
// per version once the shortfall has lasted the grace, says so, and
// trains on; the metrics show the pool.
TEST(DistributedTest, ASyncLearnerServedByFewerActorsThanPlannedTrainsOn) {
  const std::string run = FreshDirectory("short");
  const Learner learner = StartLearner(
      "--steps=2048 --horizon=256 --envs=4 --seed=3 --metrics=127.0.0.1:0 "
      "--run_dir=" +
      run);
  const int port = MetricsPort(learner.err, "learner");
  ASSERT_GT(port, 0) << ReadFile(learner.err);
  const int actor = StartVantage(ActorCommand(learner, 2), TempPath("a.out"),
                                 TempPath("a.err"));
  const std::string said =
      "1 actors with 2 env slots are live (the run plans 4)";
  for (int i = 0;
       i < 600 && ReadFile(learner.err).find(said) == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  EXPECT_THAT(ReadFile(learner.err), HasSubstr(said));
  absl::StatusOr<std::string> text = HttpGet(port, "/metrics");
  ASSERT_TRUE(text.ok()) << text.status();
  EXPECT_EQ(Sample(*text, "vantage_learner_live_env_slots"), 2);
  EXPECT_EQ(WaitVantage(learner.pid, 120), 0) << ReadFile(learner.err);
  EXPECT_EQ(WaitVantage(actor, 20), 0);
  EXPECT_EQ(ProgressValues(run, "batch_env_slots"),
            (std::vector<std::string>{"2", "2"}));
  EXPECT_EQ(ProgressValues(run, "batch_actors"),
            (std::vector<std::string>{"1", "1"}));
  EXPECT_EQ(ProgressValues(run, "rejected_segments").back(), "0");
}

// An asynchronous run served by fewer actors than planned fills its
// batches too: the one actor's grant grows until it can (its lead of two
// versions' grants would otherwise run out before the batch is full).
TEST(DistributedTest, AnAsynchronousLearnerServedByFewerActorsTrainsOn) {
  const std::string run = FreshDirectory("short_async");
  const Learner learner = StartLearner(
      "--steps=4096 --horizon=256 --envs=8 --nosync --max_policy_lag=4 "
      "--seed=3 --run_dir=" +
      run);
  const int actor = StartVantage(ActorCommand(learner, 1), TempPath("a.out"),
                                 TempPath("a.err"));
  EXPECT_EQ(WaitVantage(learner.pid, 120), 0) << ReadFile(learner.err);
  EXPECT_EQ(WaitVantage(actor, 20), 0);
  EXPECT_THAT(ReadFile(learner.err),
              HasSubstr("1 actors with 1 env slots are live (the run plans 8) "
                        "and have sent their grant"));
  EXPECT_EQ(ProgressValues(run, "batch_actors"),
            (std::vector<std::string>{"1", "1"}));
}

// More actors than planned make bigger batches, sooner: every slot acts one
// horizon per version, and every rollout they send is trained on (none is
// stale, none thrown away).
TEST(DistributedTest, ExtraActorsEnlargeTheSyncBatchAndNothingIsStale) {
  const std::string run = FreshDirectory("extra");
  const Learner learner = StartLearner(
      "--steps=6144 --horizon=256 --envs=2 --seed=4 --run_dir=" + run);
  std::vector<int> actors;
  for (int i = 0; i < 3; ++i) {
    actors.push_back(StartVantage(ActorCommand(learner, 1), TempPath("a.out"),
                                  TempPath("a.err")));
  }
  EXPECT_EQ(WaitVantage(learner.pid, 120), 0) << ReadFile(learner.err);
  for (int actor : actors) EXPECT_EQ(WaitVantage(actor, 20), 0);
  const std::vector<std::string> slots = ProgressValues(run, "batch_env_slots");
  EXPECT_EQ(slots.back(), "3");
  EXPECT_EQ(ProgressValues(run, "rejected_segments").back(), "0");
  const std::vector<std::string> steps = ProgressValues(run, "env_steps");
  EXPECT_EQ(steps.size(), slots.size());
  int64_t sum = 0;
  for (const std::string& n : slots) sum += 256 * std::stoll(n);
  EXPECT_EQ(std::to_string(sum), steps.back());
}

// A killed actor (its calls end at once) leaves the pool: the sync learner
// does not wait for it, and the one left fills the batches.
TEST(DistributedTest, AKilledActorDoesNotStallASyncLearner) {
  const std::string run = FreshDirectory("killed");
  const Learner learner = StartLearner(
      "--steps=8192 --horizon=256 --envs=4 --seed=6 --run_dir=" + run);
  const int survivor = StartVantage(ActorCommand(learner, 2), TempPath("a.out"),
                                    TempPath("a.err"));
  const int victim = StartVantage(ActorCommand(learner, 2), TempPath("a.out"),
                                  TempPath("a.err"));
  for (int i = 0; i < 1200 && ProgressValues(run, "env_steps").size() < 2;
       ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
  kill(victim, SIGKILL);
  WaitVantage(victim, 20);
  EXPECT_EQ(WaitVantage(learner.pid, 120), 0) << ReadFile(learner.err);
  EXPECT_EQ(WaitVantage(survivor, 20), 0);
  const std::vector<std::string> slots = ProgressValues(run, "batch_env_slots");
  EXPECT_EQ(slots.front(), "4");
  EXPECT_EQ(slots.back(), "2");
}

// Scrapes the learner while it trains: every column of progress.csv is a
// series of the learner's, and scrapes agree with that update's row.
TEST(DistributedTest, PrometheusCountersAgreeWithProgressCsv) {
  const std::string run = FreshDirectory("metrics");
  const Learner learner = StartLearner(
      "--steps=12288 --horizon=256 --envs=2 --seed=2 --metrics=127.0.0.1:0 "
      "--run_dir=" +
      run);
  const std::string actor_err = TempPath("actor.err");
  const int actor =
      StartVantage("actor --learner=127.0.0.1:" + learner.port +
                       " --env=InvertedPendulum --envs=2 --metrics=127.0.0.1:0",
                   TempPath("actor.out"), actor_err);
  const int learner_port = MetricsPort(learner.err, "learner");
  const int actor_port = MetricsPort(actor_err, "actor");
  ASSERT_GT(learner_port, 0) << ReadFile(learner.err);
  ASSERT_GT(actor_port, 0) << ReadFile(actor_err);
  int agreeing = 0;
  double actor_steps = 0;
  // Scrape while the learner serves (an exited learner stays a zombie until
  // WaitVantage reaps it, so its endpoint going away ends the loop). Two
  // scrapes take about as long as an update here: 24 updates give several
  // chances to land between two.
  bool served = false;
  for (int i = 0; i < 1200 && agreeing < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    absl::StatusOr<std::string> text = HttpGet(learner_port, "/metrics");
    absl::StatusOr<std::string> actor_text = HttpGet(actor_port, "/metrics");
    if (actor_text.ok()) {
      actor_steps = Sample(*actor_text, "vantage_actor_env_steps_total");
    }
    if (!text.ok() && served) break;
    if (!text.ok()) continue;
    served = true;
    const int version =
        static_cast<int>(Sample(*text, "vantage_learner_policy_version"));
    const std::vector<std::string> rows = DeterministicProgress(run);
    if (version < 1 || version >= static_cast<int>(rows.size())) continue;
    const std::vector<std::string> row = absl::StrSplit(rows[version], ',');
    // Every column of the row is a series of the learner's (one table
    // feeds both). A scrape may fall between two updates' reports: count
    // only those that agree on every column (the wall-clock ones aside).
    bool whole = true;
    for (size_t c = 0; c < ProgressColumns().size(); ++c) {
      const ProgressColumn& column = ProgressColumns()[c];
      const std::string name = absl::StrCat("vantage_learner_", column.metric);
      EXPECT_THAT(*text, HasSubstr("\n" + name + " ")) << column.name;
      double expected = 0;
      if (c + 2 >= ProgressColumns().size() ||
          !absl::SimpleAtod(row[c], &expected)) {
        continue;  // wall clock, or NaN (an empty field)
      }
      whole = whole && std::abs(Sample(*text, name) - expected) <=
                           1e-6 * std::max(1.0, std::abs(expected));
    }
    if (whole) {
      ++agreeing;
      EXPECT_EQ(Sample(*text, "vantage_learner_updates_total"), version);
      EXPECT_EQ(Sample(*text, "vantage_learner_live_actors"), 1);
      EXPECT_EQ(Sample(*text, "vantage_learner_registrations_total"), 1);
    }
  }
  EXPECT_GE(agreeing, 3);
  EXPECT_GT(actor_steps, 0);
  EXPECT_EQ(WaitVantage(learner.pid, 120), 0) << ReadFile(learner.err);
  kill(actor, SIGTERM);
  EXPECT_EQ(WaitVantage(actor, 30), 0);
}

TEST(DistributedTest, AnActorOfAnotherEnvironmentIsRefused) {
  const Learner learner = StartLearner("--steps=512 --horizon=256");
  const Outcome actor = RunVantage("actor --learner=127.0.0.1:" + learner.port +
                                   " --env=Hopper --envs=1 --max_reconnects=0");
  EXPECT_EQ(actor.exit_code, 1);
  EXPECT_THAT(actor.err,
              HasSubstr("this learner trains InvertedPendulum, not Hopper"));
  kill(learner.pid, SIGTERM);
  EXPECT_EQ(WaitVantage(learner.pid, 20), 0);
}

// A learner with a token refuses an actor with another one for good
// (UNAUTHENTICATED ends it without retry) and trains with the right one.
TEST(DistributedTest, OnlyAnActorWithTheLearnersTokenTakesPart) {
  const std::string token = WriteTemp("token", "learner-token-42\n");
  const std::string wrong = WriteTemp("wrong-token", "learner-token-43\n");
  const Learner learner = StartLearner(
      "--steps=1024 --horizon=256 --envs=2 --auth_token_file=" + token);
  const std::string actor_args =
      "actor --learner=127.0.0.1:" + learner.port +
      " --env=InvertedPendulum --envs=2 --auth_token_file=";
  const Outcome refused =
      RunVantage(actor_args + wrong + " --max_reconnects=0");
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_THAT(refused.err,
              HasSubstr("registration: missing or wrong auth token"));

  const int actor = StartVantage(actor_args + token, TempPath("actor.out"),
                                 TempPath("actor.err"));
  EXPECT_EQ(WaitVantage(learner.pid, 120), 0) << ReadFile(learner.err);
  kill(actor, SIGTERM);
  EXPECT_EQ(WaitVantage(actor, 20), 0) << ReadFile(TempPath("actor.err"));
  EXPECT_THAT(ReadFile(learner.out), HasSubstr("RESULT train"));
  EXPECT_THAT(ReadFile(learner.out), HasSubstr("steps=1024"));

  // Half a TLS configuration is a flag error, before anything starts.
  const Outcome half = RunVantage("learner --tls_cert=" + token);
  EXPECT_EQ(half.exit_code, 2);
  EXPECT_THAT(half.err, HasSubstr("--tls_key"));
}

TEST(DistributedTest, AnActorWithoutALearnerGivesUpWhenTold) {
  const Outcome actor = RunVantage(
      "actor --learner=127.0.0.1:1 --env=InvertedPendulum --max_reconnects=2");
  EXPECT_EQ(actor.exit_code, 1);
  EXPECT_THAT(actor.err, HasSubstr("giving up after 2 reconnects"));
  EXPECT_EQ(RunVantage("actor --envs=1").exit_code, 2);
}

// `vantage train` takes the learner's limits and passes the ones given to
// the learner it starts; out of range, or for a local run, they are usage
// errors before anything starts.
TEST(DistributedTest, TrainPassesItsLearnerLimitsOn) {
  const std::string run = FreshDirectory("limits");
  const std::string err = TempPath("train.err");
  const int train = StartVantage(
      "train --actors=1 --envs_per_actor=2 --steps=1000000 --horizon=256 "
      "--max_live_actors=7 --actor_expiry_s=33 --run_dir=" +
          run,
      TempPath("train.out"), err);
  std::vector<int> learners;
  for (int i = 0; i < 600 && learners.empty(); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    learners = ChildrenRunning(train, " learner ");
  }
  ASSERT_EQ(learners.size(), 1u) << ReadFile(err);
  std::string command_line =
      ReadFile("/proc/" + std::to_string(learners[0]) + "/cmdline");
  std::replace(command_line.begin(), command_line.end(), '\0', ' ');
  EXPECT_THAT(command_line, HasSubstr(" --max_live_actors=7 "));
  EXPECT_THAT(command_line, HasSubstr(" --actor_expiry_s=33 "));
  EXPECT_THAT(command_line, Not(HasSubstr("--max_live_env_slots")));
  kill(train, SIGTERM);
  EXPECT_EQ(WaitVantage(train, 60), 0) << ReadFile(err);

  const Outcome local = RunVantage("train --mode=local --max_live_actors=3");
  EXPECT_EQ(local.exit_code, 2);
  EXPECT_THAT(local.err, HasSubstr("--max_live_actors limits the learner of "
                                   "--mode=distributed"));
  const Outcome zero = RunVantage("train --max_live_actors=0");
  EXPECT_EQ(zero.exit_code, 2);
  EXPECT_THAT(zero.err, HasSubstr("max_live_actors must be >= 1, got 0"));
}

}  // namespace
}  // namespace vantage
