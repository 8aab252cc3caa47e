#ifndef VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_BACKEND_H_
#define VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_BACKEND_H_

// Where an experiment's cells run: each cell is one `vantage train`
// command; a backend runs a list of them (this machine's processes, or a
// cluster's scheduler) and says how each ended. Backends are chosen by
// name (`vantage experiment run --backend=NAME`).

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

namespace vantage {

struct CellTask {
  std::string name;                     // the cell's directory under EXP_DIR
  std::vector<std::string> train_args;  // `vantage` arguments: {"train", ..}
  std::string run_dir;
  std::string log_path;  // the command's output is appended here
  int64_t steps = 0;     // the run's environment steps
  // The same run as a command that may run again and again (a requeued
  // job): `train ... --run_dir=RUN_DIR --resume_if_exists`.
  std::vector<std::string> repeatable_args;
  int cores = 1;  // processes the run starts (learners and actors)
};

struct CellOutcome {
  enum class Kind { kFinished, kFailed, kStopped };
  Kind kind = Kind::kFailed;
  std::string message;  // why it failed or stopped
};

// The whole grid, for progress lines: the tasks are its unfinished cells.
struct GridTotals {
  int cells = 0;
  int finished_before = 0;
  int64_t steps = 0;         // over all cells
  int64_t steps_before = 0;  // done when this invocation started
};

class ExperimentBackend {
 public:
  virtual ~ExperimentBackend() = default;
  // Runs every task and returns their outcomes, in order. Once `stop` is
  // set, running commands are stopped cleanly (each checkpoints) and the
  // rest are not started: all of those are kStopped.
  virtual std::vector<CellOutcome> Run(const std::vector<CellTask>& tasks,
                                       const GridTotals& totals,
                                       const std::atomic<bool>& stop) = 0;
  // FailedPrecondition while cells an earlier invocation started still run
  // where this one cannot see them (a cluster's queue).
  virtual absl::Status CheckIdle() { return absl::OkStatus(); }
};

struct BackendOptions {
  int jobs = 1;          // commands at a time
  std::string work_dir;  // the backend's own files (EXP_DIR/<backend>)
  // Passed to the scheduler as they are (sbatch: --partition=.., --time=..).
  std::vector<std::string> scheduler_args;
};

// A backend by name ("local", "slurm"); an unknown name lists the known
// ones.
absl::StatusOr<std::unique_ptr<ExperimentBackend>> MakeExperimentBackend(
    const std::string& name, const BackendOptions& options);
std::vector<std::string> ExperimentBackendNames();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_BACKEND_H_
