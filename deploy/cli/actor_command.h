#ifndef VANTAGE_DEPLOY_CLI_ACTOR_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_ACTOR_COMMAND_H_

#include "actor/remote/remote_actor.h"

namespace vantage {

// `vantage actor --learner=HOST:PORT --env=NAME --envs=M`: acts and streams
// until SIGINT/SIGTERM (exit 0) or a refusal / exhausted reconnects (one
// line on stderr, exit 1).
int RunActorCommand(const RemoteActorConfig& config);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_ACTOR_COMMAND_H_
