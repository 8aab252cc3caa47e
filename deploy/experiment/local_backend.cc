// The "local" experiment backend: cells as child processes of this binary
// on this machine, `jobs` at a time, with one progress line for the grid.

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <map>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "common/util/self_process.h"
#include "deploy/experiment/experiment_backend.h"
#include "deploy/experiment/experiment_directory.h"

namespace vantage {
namespace {

using Clock = std::chrono::steady_clock;

// How long a stopped cell may take to write its checkpoint and exit (a
// distributed one stops its learner and actors first).
constexpr std::chrono::seconds kStopGrace(120);

std::string Duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  if (s >= 3600) return absl::StrCat(s / 3600, "h", (s % 3600) / 60, "m");
  return absl::StrCat(s / 60, "m", s % 60, "s");
}

std::string Count(double value) {
  if (value >= 1e6) return absl::StrFormat("%.2fM", value / 1e6);
  if (value >= 1e4) return absl::StrFormat("%.1fk", value / 1e3);
  return absl::StrFormat("%.0f", value);
}

class LocalBackend : public ExperimentBackend {
 public:
  explicit LocalBackend(const BackendOptions& options)
      : jobs_(std::max(1, options.jobs)) {}

  std::vector<CellOutcome> Run(const std::vector<CellTask>& tasks,
                               const GridTotals& totals,
                               const std::atomic<bool>& stop) override {
    // Children are reaped here: an ignored SIGCHLD inherited from the
    // parent would make the kernel reap them and waitpid fail.
    std::signal(SIGCHLD, SIG_DFL);
    Grid grid(tasks, totals);
    while (true) {
      if (stop) {
        StopAll(grid.running, tasks, grid.outcomes);
        break;
      }
      StartCells(grid, stop);
      if (grid.running.empty() && grid.next >= tasks.size()) break;
      ReapEndedCells(grid, stop);
      ShowProgress(grid);
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    if (terminal_) std::printf("\n");
    std::fflush(stdout);
    return grid.outcomes;
  }

 private:
  struct Progress {
    GridTotals totals;
    Clock::time_point started;
    int finished = 0;
    int failed = 0;
    int running = 0;
    int waiting = 0;
    int64_t steps = 0;
  };

  // One Run's cells: those running, the next to start, how each ended.
  struct Grid {
    Grid(const std::vector<CellTask>& tasks, const GridTotals& totals)
        : tasks(tasks),
          outcomes(tasks.size()),
          progress{totals, Clock::now()},
          gained(tasks.size(), 0) {
      for (CellOutcome& outcome : outcomes) {
        outcome.kind = CellOutcome::Kind::kStopped;
        outcome.message = "not started";
      }
      for (const CellTask& task : tasks) {
        start_steps.push_back(LastProgressSteps(task.run_dir));
      }
    }

    const std::vector<CellTask>& tasks;
    std::vector<CellOutcome> outcomes;
    std::map<pid_t, size_t> running;
    size_t next = 0;
    Progress progress;
    // Steps each task made in this invocation, within its run's steps.
    std::vector<int64_t> start_steps;
    std::vector<int64_t> gained;
    Clock::time_point last_count;
  };

  static void CountSteps(Grid& grid, size_t i) {
    const CellTask& task = grid.tasks[i];
    const int64_t now = LastProgressSteps(task.run_dir);
    grid.gained[i] = std::clamp<int64_t>(
        now - grid.start_steps[i], 0,
        std::max<int64_t>(0, task.steps - grid.start_steps[i]));
  }

  // Up to `jobs_` at a time; a cell that cannot start has failed.
  void StartCells(Grid& grid, const std::atomic<bool>& stop) {
    while (!stop && static_cast<int>(grid.running.size()) < jobs_ &&
           grid.next < grid.tasks.size()) {
      const CellTask& task = grid.tasks[grid.next];
      absl::StatusOr<pid_t> pid =
          SpawnSelf(task.train_args, task.log_path, /*append=*/true);
      if (pid.ok()) {
        grid.running[*pid] = grid.next;
      } else {
        grid.outcomes[grid.next] = {CellOutcome::Kind::kFailed,
                                    std::string(pid.status().message())};
        ++grid.progress.failed;
        Report(grid.progress, "failed", task.name,
               grid.outcomes[grid.next].message);
      }
      ++grid.next;
    }
  }

  void ReapEndedCells(Grid& grid, const std::atomic<bool>& stop) {
    for (auto it = grid.running.begin(); it != grid.running.end();) {
      int status = 0;
      const pid_t ended = waitpid(it->first, &status, WNOHANG);
      if (ended == 0 || (ended < 0 && errno == EINTR)) {
        ++it;
        continue;
      }
      // ended < 0 otherwise: the child is gone without a status to read;
      // its progress.csv still says how far it got.
      const size_t index = it->second;
      const CellTask& task = grid.tasks[index];
      CellOutcome& outcome = grid.outcomes[index];
      outcome = Classify(task, ended > 0 ? status : -1, stop);
      CountSteps(grid, index);
      it = grid.running.erase(it);
      grid.progress.running = static_cast<int>(grid.running.size());
      if (outcome.kind == CellOutcome::Kind::kFinished) {
        ++grid.progress.finished;
        Report(grid.progress, "finished", task.name, "");
      } else if (outcome.kind == CellOutcome::Kind::kFailed) {
        ++grid.progress.failed;
        Report(grid.progress, "failed", task.name, outcome.message);
      }
    }
  }

  void ShowProgress(Grid& grid) {
    Progress& progress = grid.progress;
    progress.running = static_cast<int>(grid.running.size());
    progress.waiting = static_cast<int>(grid.tasks.size() - grid.next);
    // Reading the running cells' progress files once a second is enough
    // for a progress line.
    if (Clock::now() - grid.last_count >= std::chrono::seconds(1)) {
      for (const auto& [pid, index] : grid.running) CountSteps(grid, index);
      grid.last_count = Clock::now();
    }
    progress.steps = progress.totals.steps_before;
    for (int64_t steps : grid.gained) progress.steps += steps;
    PrintProgress(progress);
  }

  // How a cell's command ended: its progress.csv says whether the run is
  // complete; `stopped` tells an interruption from a failure.
  static CellOutcome Classify(const CellTask& task, int status, bool stopped) {
    const int64_t steps = LastProgressSteps(task.run_dir);
    if (steps >= task.steps) return {CellOutcome::Kind::kFinished, ""};
    if (stopped) {
      return {CellOutcome::Kind::kStopped,
              absl::StrCat("stopped at ", steps, " of ", task.steps, " steps")};
    }
    // A negative status: the child ended without one to read (see Run).
    std::string how = "an end with no status";
    if (status >= 0 && WIFEXITED(status)) {
      how = absl::StrCat("exit code ", WEXITSTATUS(status));
    } else if (status >= 0 && WIFSIGNALED(status)) {
      how = absl::StrCat("signal ", WTERMSIG(status));
    }
    return {CellOutcome::Kind::kFailed,
            absl::StrCat(how, " at ", steps, " of ", task.steps, " steps; ",
                         task.log_path, ": ", LastLogLine(task.log_path))};
  }

  void StopAll(std::map<pid_t, size_t>& running,
               const std::vector<CellTask>& tasks,
               std::vector<CellOutcome>& outcomes) {
    if (terminal_) std::printf("\n");
    std::printf(
        "experiment: stopping %zu running cells (each writes a "
        "checkpoint)\n",
        running.size());
    std::fflush(stdout);
    for (const auto& [pid, index] : running) kill(pid, SIGTERM);
    const Clock::time_point deadline = Clock::now() + kStopGrace;
    for (const auto& [pid, index] : running) {
      int status = 0;
      while (waitpid(pid, &status, WNOHANG) == 0) {
        if (Clock::now() > deadline) {
          kill(pid, SIGKILL);
          while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
          }
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
      outcomes[index] = Classify(tasks[index], status, /*stopped=*/true);
    }
    running.clear();
  }

  void Report(const Progress& progress, const char* what,
              const std::string& name, const std::string& message) {
    if (terminal_) std::printf("\r\033[K");
    std::printf("experiment: %s %s%s%s\n", what, name.c_str(),
                message.empty() ? "" : ": ", message.c_str());
    last_line_.clear();
    PrintProgress(progress);
  }

  void PrintProgress(const Progress& p) {
    const double elapsed =
        std::chrono::duration<double>(Clock::now() - p.started).count();
    const double rate =
        elapsed > 0 ? (p.steps - p.totals.steps_before) / elapsed : 0;
    const double remaining = static_cast<double>(p.totals.steps - p.steps);
    const std::string counts =
        absl::StrFormat("cells %d/%d done, %d running, %d failed, %d waiting",
                        p.totals.finished_before + p.finished, p.totals.cells,
                        p.running, p.failed, p.waiting);
    const std::string line = absl::StrCat(
        counts, " | steps ", Count(static_cast<double>(p.steps)), "/",
        Count(static_cast<double>(p.totals.steps)), ", ", Count(rate),
        " steps/s, ETA ", rate > 0 ? Duration(remaining / rate) : "?");
    const Clock::time_point now = Clock::now();
    if (terminal_) {
      if (now - last_print_ < std::chrono::seconds(1) && !last_line_.empty()) {
        return;
      }
      std::printf("\r\033[Kexperiment: %s", line.c_str());
    } else {
      // A log gets a line when the counts change, and once a minute.
      if (counts == last_counts_ &&
          now - last_print_ < std::chrono::seconds(60)) {
        return;
      }
      std::printf("experiment: %s\n", line.c_str());
    }
    std::fflush(stdout);
    last_print_ = now;
    last_line_ = line;
    last_counts_ = counts;
  }

  const int jobs_;
  const bool terminal_ = ::isatty(STDOUT_FILENO) == 1;
  Clock::time_point last_print_;
  std::string last_line_;
  std::string last_counts_;
};

}  // namespace

absl::StatusOr<std::unique_ptr<ExperimentBackend>> MakeLocalBackend(
    const BackendOptions& options) {
  return std::make_unique<LocalBackend>(options);
}

}  // namespace vantage
