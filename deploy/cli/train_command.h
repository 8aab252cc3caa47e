#ifndef VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_

#include "deploy/cli/command.h"
#include "deploy/cli/run_request.h"

namespace vantage {

// `vantage train`: a whole run on this machine, distributed (a learner and
// actor processes over loopback gRPC, deploy/run/launcher.h) or local (one
// process); a progress line while a terminal watches and the RESULT train
// line at the end.
Command TrainCommand();

// What train and learner check before any work starts, so that a run that
// cannot start is a usage error (exit 2) and not a failure to restart: the
// environment exists, and the run directory is free (new run) or holds a
// run (resume), or holds this run before its first checkpoint
// (--resume_if_exists: started over).
absl::Status CheckRunCanStart(const ResolvedRun& run);

// Clears the run directory of a run that starts over (`run.start_over`);
// nothing otherwise.
absl::Status PrepareRunDirectory(const ResolvedRun& run);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_
