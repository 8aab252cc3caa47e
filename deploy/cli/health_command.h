#ifndef VANTAGE_DEPLOY_CLI_HEALTH_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_HEALTH_COMMAND_H_

#include "deploy/cli/command.h"

namespace vantage {

// `vantage health --learner=HOST:PORT`: exit 0 once the learner's
// grpc.health.v1 service answers SERVING, exit 1 if it does not within
// --timeout_s.
Command HealthCommand();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_HEALTH_COMMAND_H_
