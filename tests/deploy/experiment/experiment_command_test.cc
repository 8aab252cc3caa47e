// `vantage experiment run` against the real binary: a tiny grid runs,
// stops cleanly on SIGTERM, resumes to what an uninterrupted run gives,
// skips what is finished, reports failed cells and refuses a changed grid.

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "absl/strings/str_cat.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/deploy/cli/run_vantage.h"
#include "tests/fakes/run_files.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

// 2 estimators x 2 seeds of PPO on InvertedPendulum, 48 updates of 512
// steps each (10 epochs, so that an update takes long enough for a stop to
// land mid-run), a checkpoint every 4.
std::string TinyExperiment(const std::string& name, int64_t steps = 24576) {
  return WriteTemp(name, absl::StrCat(R"({
    "name": "tiny",
    "base": {"mode": "local",
             "training": {"env": "InvertedPendulum", "steps": ")",
                                      steps, R"(", "horizon": "512"},
             "ppo": {"epochs": 10, "minibatches": 4},
             "recording": {"checkpoint_every": 4}},
    "seeds": [0, 1],
    "variants": [{"set": {"estimator": "max"}}, {"set": {"estimator": "gae"}}]
  })"));
}

const std::vector<std::string> kCells = {
    "InvertedPendulum/max-rho0.4-E1-16-64-2048/seed-0",
    "InvertedPendulum/max-rho0.4-E1-16-64-2048/seed-1",
    "InvertedPendulum/gae/seed-0", "InvertedPendulum/gae/seed-1"};

void Overwrite(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::trunc) << text;
}

int ProgressRows(const std::string& run_dir) {
  const std::vector<std::string> lines = DeterministicProgress(run_dir);
  return lines.empty() ? 0 : static_cast<int>(lines.size()) - 1;
}

TEST(ExperimentCommandTest, StoppedAndResumedGridEqualsAnUninterruptedOne) {
  const std::string file = TinyExperiment("tiny.json");
  const std::string whole = FreshDirectory("whole");
  const Outcome uninterrupted = RunVantage(
      absl::StrCat("experiment run ", file, " --out=", whole, " --jobs=2"));
  ASSERT_EQ(uninterrupted.exit_code, 0) << uninterrupted.err;
  EXPECT_THAT(uninterrupted.out, HasSubstr("4 of 4 cells finished"));
  EXPECT_TRUE(std::filesystem::exists(whole + "/experiment.json"));
  EXPECT_TRUE(std::filesystem::exists(whole + "/base.json"));
  for (const std::string& cell : kCells) {
    EXPECT_EQ(ProgressRows(absl::StrCat(whole, "/", cell)), 48) << cell;
    EXPECT_THAT(ReadFile(absl::StrCat(whole, "/", cell, "/train.log")),
                HasSubstr("RESULT train"));
  }

  // One cell at a time; SIGTERM once the first has made some updates.
  const std::string broken = FreshDirectory("broken");
  const std::string out = TempPath("run.out");
  const std::string err = TempPath("run.err");
  const int pid = StartVantage(
      absl::StrCat("experiment run ", file, " --out=", broken, " --jobs=1"),
      out, err);
  const std::string first = absl::StrCat(broken, "/", kCells[0]);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (ProgressRows(first) < 5 &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_GE(ProgressRows(first), 5);
  kill(pid, SIGTERM);
  EXPECT_EQ(WaitVantage(pid, 120), 1);
  EXPECT_THAT(ReadFile(err), HasSubstr("the same command again resumes them"));
  EXPECT_THAT(ReadFile(out), HasSubstr("stopping 1 running cells"));
  const int rows_at_stop = ProgressRows(first);
  ASSERT_LT(rows_at_stop, 48) << "the cell finished before the stop";
  // The stopped cell kept every update: its newest checkpoint is its last
  // row's, not the last periodic one.
  EXPECT_TRUE(std::filesystem::exists(
      absl::StrCat(first, "/checkpoints/checkpoint-",
                   std::string(8 - std::to_string(rows_at_stop).size(), '0'),
                   rows_at_stop, ".pt")));

  const Outcome resumed = RunVantage(
      absl::StrCat("experiment run ", file, " --out=", broken, " --jobs=2"));
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_THAT(resumed.out, HasSubstr("1 to resume, 3 to start"));
  for (const std::string& cell : kCells) {
    EXPECT_EQ(DeterministicProgress(absl::StrCat(broken, "/", cell)),
              DeterministicProgress(absl::StrCat(whole, "/", cell)))
        << cell;
  }

  // Finished cells are not run again.
  const Outcome again =
      RunVantage(absl::StrCat("experiment run ", file, " --out=", broken));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_THAT(again.out, HasSubstr("4 cells (4 finished, 0 to resume, 0 to "
                                   "start)"));

  // Another budget would mix two grids in one directory.
  const Outcome changed = RunVantage(absl::StrCat(
      "experiment run ", file, " --out=", broken, " --budget=0.5"));
  EXPECT_EQ(changed.exit_code, 2);
  EXPECT_THAT(changed.err,
              HasSubstr("holds a run made with other settings than this "
                        "experiment's cell"));
  EXPECT_THAT(changed.err, HasSubstr("steps"));
}

// What a repository holds of a grid (experiment.json, base.json, and per
// cell config.json and progress.csv; no checkpoints or logs) on another
// machine: the finished cells stay, a cell committed halfway starts over
// and ends as it would have, and a cell whose config.json was edited is
// refused by name.
TEST(ExperimentCommandTest, AGridAsCommittedResumesOnAnotherMachine) {
  const std::string file = TinyExperiment("committed.json", 4096);
  const std::string source = FreshDirectory("committed_source");
  const Outcome whole = RunVantage(
      absl::StrCat("experiment run ", file, " --out=", source, " --jobs=2"));
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  const std::string clone = FreshDirectory("committed_clone");
  namespace fs = std::filesystem;
  for (const char* name : {"experiment.json", "base.json"}) {
    fs::create_directories(clone);
    fs::copy_file(absl::StrCat(source, "/", name),
                  absl::StrCat(clone, "/", name));
  }
  for (const std::string& cell : kCells) {
    fs::create_directories(absl::StrCat(clone, "/", cell));
    for (const char* name : {"config.json", "progress.csv"}) {
      fs::copy_file(absl::StrCat(source, "/", cell, "/", name),
                    absl::StrCat(clone, "/", cell, "/", name));
    }
  }
  // The last cell was committed after its third update.
  const std::string halfway = absl::StrCat(clone, "/", kCells[3]);
  std::vector<std::string> rows = DeterministicProgress(halfway);
  ASSERT_EQ(rows.size(), 9u);  // the header and 8 updates
  {
    const std::string csv = ReadFile(halfway + "/progress.csv");
    size_t end = 0;
    for (int line = 0; line < 4; ++line) end = csv.find('\n', end) + 1;
    Overwrite(halfway + "/progress.csv", csv.substr(0, end));
  }
  ASSERT_EQ(ProgressRows(halfway), 3);

  const Outcome resumed = RunVantage(
      absl::StrCat("experiment run ", file, " --out=", clone, " --jobs=2"));
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_THAT(resumed.out, HasSubstr("3 finished"));
  EXPECT_THAT(resumed.out,
              HasSubstr(absl::StrCat(kCells[3],
                                     " stopped before its first "
                                     "checkpoint; starting it again")));
  for (const std::string& cell : kCells) {
    EXPECT_EQ(DeterministicProgress(absl::StrCat(clone, "/", cell)),
              DeterministicProgress(absl::StrCat(source, "/", cell)))
        << cell;
  }

  // A config.json edited by hand no longer matches its cell.
  const std::string edited = absl::StrCat(clone, "/", kCells[1]);
  std::string config = ReadFile(edited + "/config.json");
  const size_t at = config.find("\"horizon\": \"512\"");
  ASSERT_NE(at, std::string::npos) << config;
  config.replace(at, std::string("\"horizon\": \"512\"").size(),
                 "\"horizon\": \"256\"");
  Overwrite(edited + "/config.json", config);
  const Outcome refused = RunVantage(
      absl::StrCat("experiment run ", file, " --out=", clone, " --jobs=2"));
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_THAT(refused.err, HasSubstr(edited));
  EXPECT_THAT(refused.err, HasSubstr("horizon"));
}

TEST(ExperimentCommandTest, AFailedCellIsReportedAndTheOthersGoOn) {
  const std::string file = TinyExperiment("small.json", 1024);
  const std::string dir = FreshDirectory("failing");
  // The cell's log cannot be opened, so its command cannot start.
  std::filesystem::create_directories(
      absl::StrCat(dir, "/", kCells[1], "/train.log"));
  const Outcome outcome = RunVantage(
      absl::StrCat("experiment run ", file, " --out=", dir, " --jobs=1"));
  EXPECT_EQ(outcome.exit_code, 1);
  EXPECT_THAT(outcome.out, HasSubstr(absl::StrCat("failed ", kCells[1])));
  EXPECT_THAT(outcome.out, HasSubstr("3 of 4 cells finished"));
  EXPECT_THAT(outcome.err,
              HasSubstr(absl::StrCat("1 of 4 cells failed (their train.log "
                                     "says why): ",
                                     kCells[1])));
  for (const std::string& cell : {kCells[0], kCells[2], kCells[3]}) {
    EXPECT_EQ(ProgressRows(absl::StrCat(dir, "/", cell)), 2) << cell;
  }
}

// While a runner or any of its cells lives, another runner keeps out.
TEST(ExperimentCommandTest, ADirectoryInUseIsRefused) {
  const std::string dir = FreshDirectory("in_use");
  std::filesystem::create_directories(dir);
  const int fd = open((dir + "/.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX | LOCK_NB), 0);
  const Outcome outcome = RunVantage(absl::StrCat(
      "experiment run ", TinyExperiment("busy.json"), " --out=", dir));
  close(fd);
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_THAT(outcome.err, HasSubstr("is in use by another `vantage "
                                     "experiment run`"));
  EXPECT_FALSE(std::filesystem::exists(dir + "/experiment.json"));
}

// A runner killed outright leaves its cells running; they keep the
// directory until they end.
TEST(ExperimentCommandTest, CellsOfAKilledRunnerKeepTheDirectory) {
  const std::string file = TinyExperiment("orphans.json", 65536);
  const std::string dir = FreshDirectory("orphans");
  const int pid = StartVantage(
      absl::StrCat("experiment run ", file, " --out=", dir, " --jobs=1"),
      TempPath("orphans.out"), TempPath("orphans.err"));
  const std::string first = absl::StrCat(dir, "/", kCells[0]);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (ProgressRows(first) < 1 &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ASSERT_GE(ProgressRows(first), 1);
  kill(pid, SIGKILL);
  WaitVantage(pid, 10);
  const Outcome second = RunVantage(
      absl::StrCat("experiment run ", file, " --out=", dir, " --jobs=1"));
  EXPECT_EQ(second.exit_code, 2);
  EXPECT_THAT(second.err, HasSubstr("is in use by another"));
  EXPECT_LT(ProgressRows(first), 128) << "the orphan ended too early to test";
  // The orphaned cell finishes its run, then the directory is free.
  const int fd = open((dir + "/.lock").c_str(), O_RDWR);
  ASSERT_GE(fd, 0);
  const auto finish_deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(300);
  while (flock(fd, LOCK_EX | LOCK_NB) != 0 &&
         std::chrono::steady_clock::now() < finish_deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  close(fd);
  EXPECT_EQ(ProgressRows(first), 128);
}

TEST(ExperimentCommandTest, DryRunPrintsEachCellsCommand) {
  const std::string file = TinyExperiment("dry.json");
  const Outcome outcome =
      RunVantage(absl::StrCat("experiment run ", file,
                              " --dry_run --budget=0.5 --seeds=5 "
                              "--only='*/gae/*'"));
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_THAT(outcome.out,
              HasSubstr("InvertedPendulum/gae/seed-5  (12288 steps)\n  "
                        "vantage train --config=EXP_DIR/base.json "
                        "--estimator=gae --seed=5 --steps=12288 "
                        "--run_dir=EXP_DIR/InvertedPendulum/gae/seed-5\n"));
  EXPECT_THAT(outcome.out, HasSubstr("1 cells"));
}

TEST(ExperimentCommandTest, BadInputIsOneLineNamingTheProblem) {
  const Outcome missing =
      RunVantage("experiment run /no/such/file.json --out=/tmp/x");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err,
            "vantage experiment: cannot read experiment file "
            "/no/such/file.json\n");
  const std::string bad = WriteTemp(
      "bad.json",
      R"({"base": {}, "seeds": [0], "axes": [{"flag": "rho", "values": ["0.5", "-1"]}]})");
  const Outcome invalid =
      RunVantage(absl::StrCat("experiment run ", bad, " --dry_run"));
  EXPECT_EQ(invalid.exit_code, 2);
  EXPECT_THAT(invalid.err, HasSubstr("the cell of axes[0].values[1], seed 0"));
  EXPECT_EQ(std::count(invalid.err.begin(), invalid.err.end(), '\n'), 1);
  const Outcome no_out = RunVantage(absl::StrCat("experiment run ", bad));
  EXPECT_EQ(no_out.exit_code, 2);
  EXPECT_THAT(no_out.err, HasSubstr("run needs --out=EXP_DIR"));
  const Outcome unknown = RunVantage("experiment walk x");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.err, HasSubstr("unknown subcommand 'walk'"));
  const Outcome backend = RunVantage(
      absl::StrCat("experiment run ", bad, " --dry_run --backend=moon"));
  EXPECT_EQ(backend.exit_code, 2);
  EXPECT_THAT(backend.err,
              HasSubstr("--backend: unknown backend 'moon'; backends: local"));
  const Outcome only =
      RunVantage(absl::StrCat("experiment run ", TinyExperiment("only.json"),
                              " --dry_run --only=nope"));
  EXPECT_EQ(only.exit_code, 2);
  EXPECT_THAT(only.err, HasSubstr("--only=nope matches none of the 4 cells"));
}

}  // namespace
}  // namespace vantage
