#include "common/rollout/value_limits.h"

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

absl::Status CheckLimit(double value, const char* name) {
  if (!(value > 0)) {
    return absl::InvalidArgumentError(
        absl::StrCat(name, " must be > 0, got ", value));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ValueLimits::Validate() const {
  for (absl::Status status :
       {CheckLimit(max_abs_observation, "max_abs_observation"),
        CheckLimit(max_abs_action, "max_abs_action"),
        CheckLimit(max_abs_reward, "max_abs_reward"),
        CheckLimit(max_abs_log_prob, "max_abs_log_prob")}) {
    if (!status.ok()) return status;
  }
  return absl::OkStatus();
}

}  // namespace vantage
