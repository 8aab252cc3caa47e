#include "deploy/experiment/experiment_runner.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "deploy/experiment/experiment_backend.h"

namespace vantage {
namespace {

// An exclusive lock on EXP_DIR/.lock for as long as this runner or any cell
// it started lives: the descriptor is inherited by the cells (no
// close-on-exec), so cells orphaned by a killed runner still hold it and a
// second runner cannot start the same runs beside them.
class DirectoryLock {
 public:
  static absl::StatusOr<DirectoryLock> Take(const std::string& exp_dir) {
    const std::string path = exp_dir + "/.lock";
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT, 0644);
    if (fd < 0) {
      return absl::FailedPreconditionError(
          absl::StrCat("cannot open ", path, ": ", std::strerror(errno)));
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(fd);
      return absl::FailedPreconditionError(absl::StrCat(
          exp_dir,
          " is in use by another `vantage experiment run` (or by cells it "
          "started, which go on after it is killed)"));
    }
    return DirectoryLock(fd);
  }
  DirectoryLock(DirectoryLock&& other) : fd_(other.fd_) { other.fd_ = -1; }
  DirectoryLock& operator=(DirectoryLock&&) = delete;
  ~DirectoryLock() {
    if (fd_ >= 0) ::close(fd_);
  }

 private:
  explicit DirectoryLock(int fd) : fd_(fd) {}
  int fd_;
};

int CoresPerCell(const pb::RunConfig& config) {
  if (config.mode() != "distributed") return 1;
  return std::max(
      1, config.distributed().learners() + config.distributed().actors());
}

}  // namespace

int DefaultJobs(const pb::ExpandedExperiment& experiment) {
  int widest = 1;
  for (const pb::ExperimentCell& cell : experiment.cells()) {
    widest = std::max(widest, CoresPerCell(cell.config()));
  }
  const int cores =
      std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  return std::max(1, cores / widest);
}

std::vector<std::string> TrainArguments(const ExperimentDirectory& directory,
                                        const pb::ExperimentCell& cell,
                                        bool resume) {
  const std::string run_dir = directory.RunDir(cell);
  if (resume) return {"train", absl::StrCat("--resume=", run_dir)};
  std::vector<std::string> args = {
      "train", absl::StrCat("--config=", directory.BaseConfigPath())};
  // Sorted, so that the same cell is always the same command.
  const std::map<std::string, std::string> flags(cell.flags().begin(),
                                                 cell.flags().end());
  for (const auto& [flag, value] : flags) {
    args.push_back(absl::StrCat("--", flag, "=", value));
  }
  args.push_back(absl::StrCat("--run_dir=", run_dir));
  return args;
}

namespace {

// What is left of the grid to run: every cell not finished, in the order
// to run them, counted into `totals` and `resumed`.
absl::StatusOr<std::vector<CellTask>> PlanCells(
    const pb::ExpandedExperiment& experiment,
    const ExperimentDirectory& directory, GridTotals& totals, int& resumed) {
  totals.cells = experiment.cells_size();
  std::vector<CellTask> tasks;
  std::vector<uint64_t> seeds;
  for (const pb::ExperimentCell& cell : experiment.cells()) {
    const int64_t steps = cell.config().training().steps();
    totals.steps += steps;
    CellStatus status = directory.Inspect(cell);
    if (status.state == CellState::kFinished) {
      ++totals.finished_before;
      totals.steps_before += steps;
      continue;
    }
    if (status.state == CellState::kNoCheckpoint) {
      std::printf(
          "experiment: %s stopped before its first checkpoint; starting it "
          "again\n",
          cell.dir().c_str());
      if (absl::Status cleared = directory.ClearRun(cell); !cleared.ok()) {
        return cleared;
      }
      status = CellStatus();
    }
    const bool resume = status.state == CellState::kResumable;
    resumed += resume ? 1 : 0;
    totals.steps_before += status.env_steps;
    std::error_code error;
    std::filesystem::create_directories(directory.RunDir(cell), error);
    if (error) {
      return absl::FailedPreconditionError(absl::StrCat(
          "cannot create ", directory.RunDir(cell), ": ", error.message()));
    }
    CellTask task;
    task.name = cell.dir();
    task.train_args = TrainArguments(directory, cell, resume);
    task.run_dir = directory.RunDir(cell);
    task.log_path = directory.LogPath(cell);
    task.steps = steps;
    task.repeatable_args = TrainArguments(directory, cell, /*resume=*/false);
    task.repeatable_args.push_back("--resume_if_exists");
    task.cores = CoresPerCell(cell.config());
    seeds.push_back(cell.seed());
    tasks.push_back(std::move(task));
  }
  // Seed by seed, so that a grid stopped halfway holds whole comparisons
  // (every group, the baseline among them, with the first seeds) rather
  // than some groups with all their seeds and others with none.
  std::vector<size_t> order(tasks.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return seeds[a] < seeds[b]; });
  std::vector<CellTask> ordered;
  for (size_t i : order) ordered.push_back(std::move(tasks[i]));
  return ordered;
}

// Says how many cells finished; an error names the failed cells, or how
// many were stopped.
absl::Status Conclude(const pb::ExpandedExperiment& experiment,
                      const std::vector<CellTask>& tasks,
                      const GridTotals& totals,
                      const std::vector<CellOutcome>& outcomes) {
  std::vector<std::string> failed;
  int stopped = 0;
  for (size_t i = 0; i < tasks.size(); ++i) {
    if (outcomes[i].kind == CellOutcome::Kind::kFailed) {
      failed.push_back(tasks[i].name);
    } else if (outcomes[i].kind == CellOutcome::Kind::kStopped) {
      ++stopped;
    }
  }
  const int finished = totals.cells - static_cast<int>(failed.size()) - stopped;
  std::printf("experiment %s: %d of %d cells finished\n",
              experiment.name().c_str(), finished, totals.cells);
  std::fflush(stdout);
  if (!failed.empty()) {
    return absl::AbortedError(
        absl::StrCat(failed.size(), " of ", totals.cells,
                     " cells failed (their train.log says why): ",
                     absl::StrJoin(failed, ", "),
                     stopped > 0 ? absl::StrCat("; ", stopped, " stopped") : "",
                     "; the same command again retries them"));
  }
  if (stopped > 0) {
    return absl::CancelledError(
        absl::StrCat("stopped with ", stopped,
                     " cells unfinished; the same command again resumes "
                     "them"));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status RunExperiment(const pb::ExpandedExperiment& experiment,
                           const pb::RunConfig& base,
                           const ExperimentRunOptions& options,
                           const std::atomic<bool>& stop) {
  const ExperimentDirectory directory(options.exp_dir);
  std::error_code error;
  std::filesystem::create_directories(options.exp_dir, error);
  if (error) {
    return absl::FailedPreconditionError(
        absl::StrCat("cannot create experiment directory ", options.exp_dir,
                     ": ", error.message()));
  }
  absl::StatusOr<DirectoryLock> lock = DirectoryLock::Take(options.exp_dir);
  if (!lock.ok()) return lock.status();
  BackendOptions backend_options;
  backend_options.jobs =
      options.jobs > 0 ? options.jobs : DefaultJobs(experiment);
  backend_options.work_dir =
      absl::StrCat(options.exp_dir, "/", options.backend);
  backend_options.scheduler_args = options.scheduler_args;
  absl::StatusOr<std::unique_ptr<ExperimentBackend>> backend =
      MakeExperimentBackend(options.backend, backend_options);
  if (!backend.ok()) return backend.status();
  if (absl::Status idle = (*backend)->CheckIdle(); !idle.ok()) return idle;
  if (absl::Status status = directory.Prepare(experiment, base); !status.ok()) {
    return status;
  }
  std::filesystem::create_directories(backend_options.work_dir, error);

  GridTotals totals;
  int resumed = 0;
  absl::StatusOr<std::vector<CellTask>> tasks =
      PlanCells(experiment, directory, totals, resumed);
  if (!tasks.ok()) return tasks.status();
  std::printf(
      "experiment %s: %d cells (%d finished, %d to resume, %zu to start), "
      "%d at a time (%s backend), in %s\n",
      experiment.name().empty() ? "(unnamed)" : experiment.name().c_str(),
      totals.cells, totals.finished_before, resumed, tasks->size() - resumed,
      backend_options.jobs, options.backend.c_str(), options.exp_dir.c_str());
  std::fflush(stdout);
  return Conclude(experiment, *tasks, totals,
                  (*backend)->Run(*tasks, totals, stop));
}

}  // namespace vantage
