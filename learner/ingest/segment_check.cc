#include "learner/ingest/segment_check.h"

#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {

SegmentCheck::SegmentCheck(EnvSpec spec, int64_t max_segment_steps,
                           ValueLimits value_limits, int64_t max_policy_lag,
                           int64_t core_state_size)
    : spec_(std::move(spec)),
      max_segment_steps_(max_segment_steps),
      value_limits_(value_limits),
      max_policy_lag_(max_policy_lag),
      core_state_size_(core_state_size) {}

absl::Status SegmentCheck::Validate(const Segment& segment) const {
  return ValidateSegment(segment, spec_, max_segment_steps_, value_limits_,
                         core_state_size_);
}

absl::Status SegmentCheck::CheckPublished(int64_t policy_version,
                                          int64_t newest) {
  if (policy_version <= newest) return absl::OkStatus();
  return absl::FailedPreconditionError(
      absl::StrCat("segment.policy_version ", policy_version,
                   " has not been published (newest: ", newest, ")"));
}

int64_t SegmentCheck::OldestTrainable(int64_t newest) const {
  return max_policy_lag_ < 0 ? std::numeric_limits<int64_t>::min()
                             : newest - max_policy_lag_;
}

}  // namespace vantage
