#include "actor/actor_config.h"

#include "absl/strings/str_cat.h"

namespace vantage {

absl::Status ActorConfig::Validate() const {
  if (env.empty()) return absl::InvalidArgumentError("actor needs an env");
  if (num_envs < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("actor needs num_envs >= 1, got ", num_envs));
  }
  if (segment_length < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("actor needs segment_length >= 1, got ", segment_length));
  }
  if (!(observation_clip > 0)) {
    return absl::InvalidArgumentError("observation_clip must be > 0");
  }
  return absl::OkStatus();
}

}  // namespace vantage
