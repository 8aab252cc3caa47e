#include "deploy/cli/actor_command.h"

#include <ATen/Parallel.h>

#include <cstdio>
#include <string>

#include "deploy/cli/stop_signal.h"

namespace vantage {

int RunActorCommand(const RemoteActorConfig& config) {
  if (config.num_envs < 1 || config.learner.empty()) {
    std::fprintf(stderr,
                 "vantage actor: --learner=HOST:PORT and --envs >= 1 are "
                 "required\n");
    return 2;
  }
  // One intra-op thread per actor: actors are many processes already.
  at::set_num_threads(1);
  const absl::Status status = RunRemoteActor(config, StopRequested());
  if (!status.ok()) {
    std::fprintf(stderr, "vantage actor: %s\n",
                 std::string(status.message()).c_str());
    return 1;
  }
  return 0;
}

}  // namespace vantage
