#ifndef VANTAGE_ACTOR_RUN_SETTINGS_H_
#define VANTAGE_ACTOR_RUN_SETTINGS_H_

// What an actor takes from a run's configuration: its environments, how
// they are wrapped, its segments and the policy network it runs. One
// reading for a local run's plan and for an actor given the learner's run
// config at registration, so that the rules (frame stacking, configs from
// before a setting existed) live once.

#include "absl/status/statusor.h"
#include "actor/actor_config.h"
#include "actor/envs/env_registry.h"
#include "common/nn/network_config.h"
#include "proto/run_config.pb.h"

namespace vantage {

// The training section with the actor's settings resolved: absent ones
// given `defaults`' values (the network's and wrapping's are their
// components' own), each checked (the message names the flag). Its
// tables are in run_settings.cc.
absl::Status ResolveActorSettings(const ActorConfig& defaults,
                                  pb::TrainingSettings& training);

// The run's environment wrapping (a config from before frame stacking
// existed stacks none).
EnvOptions EnvOptionsOf(const pb::RunConfig& run);

// The policy network the run's actors run: its hidden sizes and torso (a
// config from before torsos existed built MLPs); an unknown torso is
// InvalidArgument naming it.
absl::StatusOr<NetworkConfig> PolicyNetworkOf(const pb::RunConfig& run);

// Whether the training section names a recurrent core (gru or lstm).
bool NamesACore(const pb::TrainingSettings& training);

// The actor of a resolved run config: the run's env, wrapping, env streams
// (training.envs), segment length, seed and policy network. A remote actor
// keeps its own env name, env count and seed (see ActorEnvSeed).
absl::StatusOr<ActorConfig> ActorConfigOf(const pb::RunConfig& run);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_RUN_SETTINGS_H_
