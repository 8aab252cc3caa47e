#ifndef VANTAGE_ACTOR_ENVS_ENV_REGISTRY_H_
#define VANTAGE_ACTOR_ENVS_ENV_REGISTRY_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/env/environment.h"

namespace vantage {

// A registered name ("HalfCheetah", ...) or "mjcf:/path/model.xml", wrapped
// in its time limit. An unknown name is an error that lists the valid ones.
absl::StatusOr<std::unique_ptr<Environment>> MakeEnvironment(
    absl::string_view name);

// The registered names, sorted (mjcf:PATH not included).
std::vector<std::string> RegisteredEnvironments();

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_ENV_REGISTRY_H_
