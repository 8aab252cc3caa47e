#ifndef VANTAGE_DEPLOY_CLI_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_COMMAND_H_

// A subcommand of the `vantage` tool. Each one lives in its own file under
// deploy/cli/, lists the flags it reads (absl flags, defined in its file or,
// when several commands share one, in shared_flags.cc) and is registered in
// commands.cc. A flag a command does not list is refused (see
// command_line.h), so no flag is ever silently ignored.

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "absl/status/status.h"

namespace vantage {

// A flag that is no absl flag: declared by a command from a descriptor (the
// run settings, from proto/run_config.proto) and read by the command line
// into DeclaredFlagValue (command_line.h).
struct DeclaredFlag {
  std::string name;
  std::string help;
  bool boolean = false;  // --name and --noname need no value
  // OK if the flag takes `value`; else an error that names the flag.
  std::function<absl::Status(const std::string& value)> check;
};

// Exit codes: 2 when the command line itself is wrong (a flag, a value, an
// argument, a config file's content), so running it again cannot help; 1
// for failures while running (files, peers, training).
constexpr int kUsageError = 2;
constexpr int kRuntimeError = 1;

struct Command {
  std::string name;
  std::string summary;             // one line, for `vantage help`
  std::string usage;               // e.g. "vantage rollout [flags]"
  std::string description;         // a paragraph for `vantage help NAME`
  std::vector<std::string> flags;  // the flags it reads, without "--"
  // Those of `flags` that are no absl flags.
  std::vector<DeclaredFlag> declared_flags;
  // What an absent flag means to this command where that is not the flag's
  // own default (a flag several commands share, a default that depends on
  // another flag), taken from where the command's code takes it.
  std::map<std::string, std::string> defaults;
  std::string example;  // one command line
  // Takes its own arguments out of argv (argv[0] the program, argv[1] the
  // command) before absl parses the flags: Google Benchmark's
  // --benchmark_* under `vantage bench`. May be empty.
  std::function<void(std::vector<char*>& argv)> take_own_arguments;
  // Whether it takes positional arguments after its name (`vantage bench
  // NAME`); if not, any is a usage error before it runs.
  bool takes_arguments = false;
  // The whole `vantage help NAME` text, for a command whose flags another
  // program owns (`vantage plot`); empty: made from the fields above.
  std::function<std::string()> help;
  // Runs with the positional arguments after the command's name.
  std::function<int(const std::vector<std::string>& args)> run;
};

// Prints "vantage COMMAND: MESSAGE" as one line on stderr and returns
// `code`: how every command reports what ended it.
int CommandFailure(const std::string& command, int code,
                   const std::string& message);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_COMMAND_H_
