#ifndef VANTAGE_ACTOR_ACTOR_CONFIG_H_
#define VANTAGE_ACTOR_ACTOR_CONFIG_H_

// What an actor core runs, without LibTorch: a run's plan (local) or the
// learner's run config (remote, see actor/run_settings.h) fills it in, the
// actor core (actor/actor_core.h) runs it.

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "actor/envs/env_registry.h"
#include "common/nn/network_config.h"

namespace vantage {

struct ActorConfig {
  std::string env;
  EnvOptions env_options;
  int num_envs = 1;
  int64_t segment_length = 128;
  uint64_t seed = 0;
  int64_t actor_id = 0;
  NetworkConfig network;
  double observation_clip = 10.0;

  absl::Status Validate() const;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ACTOR_CONFIG_H_
