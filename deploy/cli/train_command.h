#ifndef VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_

#include <cstdint>
#include <string>
#include <vector>

namespace vantage {

struct TrainFlags {
  std::string mode = "local";
  std::string env = "InvertedPendulum";
  std::string algo = "ppo";
  std::string estimator = "maxabs";
  double rho = 0.4;
  std::vector<int64_t> ensemble = {1, 16, 64, 2048};
  int64_t steps = 150000;
  uint64_t seed = 0;
  int envs = 1;
  int64_t horizon = 2048;
};

// `vantage train`: one progress line per update and a final
// `RESULT train ... mean_return=<last 100 episodes>` line. Bad flags: one
// line on stderr, exit code 2.
int RunTrainCommand(const TrainFlags& flags);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_
