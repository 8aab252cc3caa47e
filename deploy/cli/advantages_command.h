#ifndef VANTAGE_DEPLOY_CLI_ADVANTAGES_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_ADVANTAGES_COMMAND_H_

#include <string>

namespace vantage {

// `vantage advantages --input=FILE.json`: the estimates of one rollout as
// JSON on stdout. Bad input: one line on stderr and exit code 2.
int RunAdvantagesCommand(const std::string& input_path);

// `vantage advantages --example`: a table of every estimator on a built-in
// rollout with a termination, a truncation and a rollout end.
int RunAdvantagesExample();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_ADVANTAGES_COMMAND_H_
