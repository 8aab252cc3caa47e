#ifndef VANTAGE_ACTOR_ENVS_ENV_REGISTRY_H_
#define VANTAGE_ACTOR_ENVS_ENV_REGISTRY_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "actor/envs/env_options.h"
#include "common/env/environment.h"

namespace vantage {

// How a run wraps every environment it makes.
struct EnvOptions {
  // > 1: each observation is the last `frame_stack` ones, oldest first
  // (see common/env/frame_stack.h); 1: as the environment gives them.
  int64_t frame_stack = 1;
  // A Python environment's factory keyword arguments, a JSON object (see
  // actor/envs/python/python_env.h); empty: none.
  std::string python_kwargs;
};

// A registered name ("HalfCheetah", ...), the same with task options
// ("HalfCheetah:ctrl_cost=0.2,max_episode_steps=500": see env_options.h),
// "mjcf:/path/model.xml", "python:MODULE:CALLABLE" or "gym:ID" (see
// actor/envs/python/python_env.h), wrapped in its time limit and then as
// `options` say. An unknown name is an error that lists the valid ones, an
// unknown task option one that lists the task's.
absl::StatusOr<std::unique_ptr<Environment>> MakeEnvironment(
    absl::string_view name, const EnvOptions& options = {});

// The registered names, sorted (mjcf:PATH not included).
std::vector<std::string> RegisteredEnvironments();

// The task options a registered name takes, with its defaults (empty for
// a task without options or an unknown name).
std::vector<EnvOptionInfo> EnvironmentOptions(const std::string& name);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_ENV_REGISTRY_H_
