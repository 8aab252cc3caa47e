#ifndef VANTAGE_DEPLOY_CLI_ENV_COMMANDS_H_
#define VANTAGE_DEPLOY_CLI_ENV_COMMANDS_H_

#include <cstdint>
#include <string>

namespace vantage {

// `vantage envs`: one line per registered environment,
// `<name> obs=<shape> act=<continuous:N|discrete:N>`.
int RunEnvsCommand();

// `vantage rollout --env=NAME --episodes=N --seed=S`: a uniform-random
// policy, one line per episode and a final line
// `RESULT rollout env=.. obs_dim=.. act_dim=.. episodes=.. mean_return=..
// mean_length=.. digest=<hex>`, the digest hashing every observation seen.
int RunRolloutCommand(const std::string& env_name, int64_t episodes,
                      uint64_t seed);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_ENV_COMMANDS_H_
