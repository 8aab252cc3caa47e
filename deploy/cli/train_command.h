#ifndef VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_

#include <string>

#include "proto/run_config.pb.h"

namespace vantage {

struct TrainRequest {
  // The fields set by flags given on the command line.
  pb::RunConfig flags;
  std::string config_file;  // --config: JSON RunConfig under the flags
  std::string run_dir;      // --run_dir: where the run is recorded
  std::string resume;       // --resume: a run directory to continue
};

// `vantage train`: a progress line while a terminal watches, a final
// `RESULT train ... mean_return=<last 100 episodes>` line. Bad flags or
// files: one line on stderr, exit code 2.
int RunTrainCommand(const TrainRequest& request);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_
