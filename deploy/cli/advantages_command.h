#ifndef VANTAGE_DEPLOY_CLI_ADVANTAGES_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_ADVANTAGES_COMMAND_H_

#include "deploy/cli/command.h"

namespace vantage {

// `vantage advantages --input=FILE.json`: the estimates of one rollout as
// JSON on stdout; `--example`: a table of every estimator on a built-in
// rollout. Bad input: one line on stderr and exit code 2.
Command AdvantagesCommand();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_ADVANTAGES_COMMAND_H_
