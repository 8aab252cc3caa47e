#ifndef VANTAGE_DEPLOY_CLI_ACTOR_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_ACTOR_COMMAND_H_

#include "deploy/cli/command.h"

namespace vantage {

// `vantage actor --learner=HOST:PORT --env=NAME --envs=M`: acts and streams
// until SIGINT/SIGTERM (exit 0) or a refusal / exhausted reconnects (one
// line on stderr, exit 1).
Command ActorCommand();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_ACTOR_COMMAND_H_
