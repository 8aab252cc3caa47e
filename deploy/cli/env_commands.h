#ifndef VANTAGE_DEPLOY_CLI_ENV_COMMANDS_H_
#define VANTAGE_DEPLOY_CLI_ENV_COMMANDS_H_

#include <cstdint>
#include <string>

namespace vantage {

// `vantage envs`: one line per registered environment,
// `<name> obs=<shape> act=<continuous:N|discrete:N>`.
int RunEnvsCommand();

struct RolloutRequest {
  std::string env;  // may be empty with a checkpoint (the run's env)
  int64_t episodes = 10;
  uint64_t seed = 0;
  std::string checkpoint;   // run directory or checkpoint file
  bool stochastic = false;  // sample instead of the mean / mode
};

// `vantage rollout --env=NAME --episodes=N --seed=S`: a uniform-random
// policy, or with --checkpoint=DIR the trained policy (deterministic by
// default); one line per episode and a final line
// `RESULT rollout env=.. obs_dim=.. act_dim=.. episodes=.. mean_return=..
// mean_length=.. digest=<hex>`, the digest hashing every observation seen.
int RunRolloutCommand(const RolloutRequest& request);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_ENV_COMMANDS_H_
