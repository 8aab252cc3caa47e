#ifndef VANTAGE_DEPLOY_EXPERIMENT_LOCAL_BACKEND_H_
#define VANTAGE_DEPLOY_EXPERIMENT_LOCAL_BACKEND_H_

#include <memory>

#include "absl/status/statusor.h"
#include "deploy/experiment/experiment_backend.h"

namespace vantage {

// Cells as child processes of this binary on this machine, options.jobs at
// a time; one progress line for the grid on stdout (updated in place on a
// terminal, a line per change and per minute otherwise). A stop sends
// SIGTERM to every running cell and waits for its checkpoint.
absl::StatusOr<std::unique_ptr<ExperimentBackend>> MakeLocalBackend(
    const BackendOptions& options);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_EXPERIMENT_LOCAL_BACKEND_H_
