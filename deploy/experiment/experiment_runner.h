#ifndef VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_RUNNER_H_
#define VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_RUNNER_H_

// Runs an expanded experiment into its directory: finished cells are
// skipped, interrupted ones resumed from their checkpoints, the rest
// started, all through a backend (experiment_backend.h).

#include <atomic>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "deploy/experiment/experiment_directory.h"
#include "proto/experiment.pb.h"

namespace vantage {

struct ExperimentRunOptions {
  std::string exp_dir;
  std::string backend = "local";
  int jobs = 0;                             // cells at a time; 0: DefaultJobs
  std::vector<std::string> scheduler_args;  // BackendOptions::scheduler_args
};

// Cells at a time that this machine's cores allow: a local-mode cell takes
// one core, a distributed one a core per learner and actor process.
int DefaultJobs(const pb::ExpandedExperiment& experiment);

// The `vantage` arguments that run a cell: a new run (`train --config=
// EXP_DIR/base.json --FLAG=VALUE... --run_dir=...`) or, with `resume`, the
// run continued (`train --resume=...`).
std::vector<std::string> TrainArguments(const ExperimentDirectory& directory,
                                        const pb::ExperimentCell& cell,
                                        bool resume);

// Cells run seed by seed (every group's first seed before any second
// one). OK when every cell has finished; otherwise an error that says which
// failed (and where their logs are) or how many a stop left unfinished.
absl::Status RunExperiment(const pb::ExpandedExperiment& experiment,
                           const pb::RunConfig& base,
                           const ExperimentRunOptions& options,
                           const std::atomic<bool>& stop);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_EXPERIMENT_EXPERIMENT_RUNNER_H_
