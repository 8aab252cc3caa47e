#ifndef VANTAGE_DEPLOY_CLI_EXPERIMENT_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_EXPERIMENT_COMMAND_H_

#include "deploy/cli/command.h"
#include "deploy/experiment/experiment_grid.h"

namespace vantage {

// `vantage experiment run FILE --out=EXP_DIR`: a grid of seeded runs
// (deploy/experiment/); `vantage experiment report EXP_DIR`: its tables,
// statistics and figures, made by deploy/experiment/report.py (which owns
// the report's flags). docs/experiments.md.
Command ExperimentCommand();

// The run flags as `vantage train` reads and resolves them, for expanding
// experiment files.
RunSettingsSchema ExperimentRunSchema();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_EXPERIMENT_COMMAND_H_
