#ifndef VANTAGE_DEPLOY_CLI_COMMAND_LINE_H_
#define VANTAGE_DEPLOY_CLI_COMMAND_LINE_H_

// `vantage <command> [flags] [arguments]`: picks the command, refuses any
// flag that is not the command's own (on the command line or in a
// --flagfile), prints help, and runs it.

#include <optional>
#include <string>
#include <vector>

#include "absl/strings/string_view.h"
#include "deploy/cli/command.h"

namespace vantage {

// Whether the flag was set by the command line, a --flagfile or
// --fromenv, as opposed to holding its default.
bool FlagGiven(absl::string_view name);

// The value a declared flag (Command::declared_flags) was given, as
// written ("true"/"false" for --name/--noname); nullopt if not given.
std::optional<std::string> DeclaredFlagValue(absl::string_view name);

// `vantage help NAME`: usage, description, every flag with its default and
// help, and the example.
std::string CommandHelp(const Command& command);
// `vantage help`: one line per command.
std::string OverviewHelp(const std::vector<Command>& commands);

// The whole of main(): argv[1] names the command (or `help`, `--help`).
int RunCommandLine(const std::vector<Command>& commands, int argc, char** argv);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_COMMAND_LINE_H_
