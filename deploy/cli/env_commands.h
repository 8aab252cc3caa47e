#ifndef VANTAGE_DEPLOY_CLI_ENV_COMMANDS_H_
#define VANTAGE_DEPLOY_CLI_ENV_COMMANDS_H_

#include "deploy/cli/command.h"

namespace vantage {

// `vantage envs`: one line per registered environment,
// `<name> obs=<shape> act=<continuous:N|discrete:N>`.
Command EnvsCommand();

// `vantage rollout --env=NAME --episodes=N --seed=S`: a uniform-random
// policy, or with --checkpoint=DIR the trained policy (deterministic by
// default); one line per episode and a final line
// `RESULT rollout env=.. obs_dim=.. act_dim=.. episodes=.. mean_return=..
// mean_length=.. digest=<hex>`, the digest hashing every observation seen.
Command RolloutCommand();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_ENV_COMMANDS_H_
