#ifndef VANTAGE_DEPLOY_EXPERIMENT_SLURM_BACKEND_H_
#define VANTAGE_DEPLOY_EXPERIMENT_SLURM_BACKEND_H_

#include <memory>

#include "absl/status/statusor.h"
#include "deploy/experiment/experiment_backend.h"

namespace vantage {

// Cells as one Slurm job array (sbatch --array=0-(N-1)%jobs, a task per
// cell, as many CPUs per task as its processes), submitted from
// options.work_dir (the tasks' commands, the array script, its output);
// this binary's path must be the same on the compute nodes. A task that
// gets TERM (time limit, preemption) checkpoints and is requeued, and its
// command resumes the run. Waits until the array leaves the queue, one
// line per change; a stop leaves the array running.
absl::StatusOr<std::unique_ptr<ExperimentBackend>> MakeSlurmBackend(
    const BackendOptions& options);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_EXPERIMENT_SLURM_BACKEND_H_
