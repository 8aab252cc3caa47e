#ifndef VANTAGE_DEPLOY_CLI_LEARNER_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_LEARNER_COMMAND_H_

#include "deploy/cli/command.h"

namespace vantage {

// `vantage learner`: serves actors over gRPC (learner/server/learner_server.h)
// and trains until the run's steps are done or SIGINT/SIGTERM; a line per
// update on stderr and the RESULT train line at the end. Exit 2 when the
// run cannot start as asked, 1 when it failed while running (which a
// launcher answers by resuming it).
Command LearnerCommand();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_LEARNER_COMMAND_H_
