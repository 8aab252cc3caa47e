#ifndef VANTAGE_DEPLOY_CLI_PLOT_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_PLOT_COMMAND_H_

#include "deploy/cli/command.h"

namespace vantage {

// `vantage plot`: learning-curve figures from run directories, drawn by
// deploy/plot/plot_runs.py with Debian's matplotlib (docs/plotting.md).
// The script owns the flags and the help; this passes the arguments on.
Command PlotCommand();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_PLOT_COMMAND_H_
