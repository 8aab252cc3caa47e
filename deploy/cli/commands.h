#ifndef VANTAGE_DEPLOY_CLI_COMMANDS_H_
#define VANTAGE_DEPLOY_CLI_COMMANDS_H_

#include <vector>

#include "deploy/cli/command.h"

namespace vantage {

// Every command of the `vantage` tool, by name; a new command is one file
// under deploy/cli/ and one line in commands.cc.
const std::vector<Command>& AllCommands();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_COMMANDS_H_
