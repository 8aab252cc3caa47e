// The `vantage` command-line tool: one binary, one subcommand per task
// (deploy/cli/commands.cc lists them).

#include "deploy/cli/command_line.h"
#include "deploy/cli/commands.h"

int main(int argc, char** argv) {
  return vantage::RunCommandLine(vantage::AllCommands(), argc, argv);
}
