#ifndef VANTAGE_DEPLOY_CLI_PYTHON_SCRIPT_H_
#define VANTAGE_DEPLOY_CLI_PYTHON_SCRIPT_H_

// Commands whose work is a Python script of the project's (figures and
// reports, drawn with Debian's matplotlib): the script owns its flags and
// help, and the command passes its arguments through.

#include <string>
#include <vector>

#include "absl/status/status.h"

namespace vantage {

// FailedPrecondition if Debian's interpreter or the script is missing.
absl::Status CheckPythonScript(const std::string& script);

// The script's --help output, or `fallback` when it cannot run.
std::string PythonScriptHelp(const std::string& script,
                             const std::string& fallback);

// Replaces this process with the script run on `args`, so that its exit
// code (0, 1 or 2, with its own one-line errors) is the command's; returns
// only on failure, with the command's exit code after a one-line message.
// The runs below the directories among `args` reach the script resolved
// (deploy/cli/resolved_run_configs.h).
int ExecPythonScript(const std::string& command, const std::string& script,
                     const std::vector<std::string>& args);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_PYTHON_SCRIPT_H_
