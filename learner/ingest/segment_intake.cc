#include "learner/ingest/segment_intake.h"

#include <algorithm>
#include <iterator>
#include <map>
#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {

namespace {

constexpr size_t kRecentReturns = 100;

}  // namespace

SegmentIntake::SegmentIntake(const LearnerConfig& config)
    : check_(config.spec, config.max_segment_steps, config.value_limits,
             config.max_policy_lag, config.network.core_state_size()),
      horizon_(config.horizon),
      rollouts_per_batch_(config.rollouts_per_batch),
      // 0 means room for 8 batches.
      max_buffered_steps_(config.max_buffered_steps > 0
                              ? config.max_buffered_steps
                              : 8 * config.horizon * config.rollouts_per_batch),
      stitcher_(config.horizon) {}

absl::StatusOr<std::vector<Rollout>> SegmentIntake::NextBatch(
    SegmentSource& source, int64_t version) {
  DropStale(version);
  int64_t size = 0;
  while ((size = BatchSize(version)) == 0) {
    absl::StatusOr<Segment> segment =
        plan_ == nullptr ? source.Receive()
                         : source.ReceiveFor(plan_->recheck_interval());
    if (absl::IsDeadlineExceeded(segment.status())) continue;
    if (!segment.ok()) return segment.status();
    Accept(*std::move(segment), source.checked(), version);
  }
  std::vector<Rollout> batch(std::make_move_iterator(pending_.begin()),
                             std::make_move_iterator(pending_.begin() + size));
  pending_.erase(pending_.begin(), pending_.begin() + size);
  return batch;
}

int64_t SegmentIntake::BatchSize(int64_t version) const {
  const int64_t total = static_cast<int64_t>(pending_.size());
  if (plan_ == nullptr) {
    return total >= rollouts_per_batch_ ? rollouts_per_batch_ : 0;
  }
  std::map<int64_t, int64_t> held;
  for (const Rollout& rollout : pending_) ++held[rollout.actor_id];
  return std::min(total, plan_->BatchSize(version, held, total));
}

void SegmentIntake::DropStale(int64_t version) {
  const int64_t oldest = check_.OldestTrainable(version);
  unreported_.stale_steps += stitcher_.DropStepsOlderThan(oldest);
  std::vector<Rollout> fresh;
  for (Rollout& rollout : pending_) {
    if (rollout.policy_versions.min().item<int64_t>() >= oldest) {
      fresh.push_back(std::move(rollout));
    } else {
      unreported_.stale_steps += rollout.policy_versions.size(0);
    }
  }
  pending_ = std::move(fresh);
}

void SegmentIntake::Accept(Segment segment, bool checked, int64_t version) {
  if (!checked) {
    absl::Status valid = check_.Validate(segment);
    if (valid.ok()) {
      valid = SegmentCheck::CheckPublished(segment.policy_version, version);
    }
    if (!valid.ok()) {
      Reject(segment.actor_id, segment.env_slot, valid);
      return;
    }
  }
  if (check_.TooStale(segment.policy_version, version)) {
    ++unreported_.rejected;
    ++unreported_.stale_segments;
    unreported_.stale_steps += segment.steps();
    return;
  }
  // Returns count only for segments the stitcher accepts (a duplicate
  // must not count twice).
  const std::vector<double> returns = segment.episode_returns;
  const int64_t actor_id = segment.actor_id;
  const int64_t env_slot = segment.env_slot;
  // Room for this segment within the budget, at the expense of the
  // streams fed least recently (an abandoned or hostile one first).
  stitcher_.EvictDownTo(
      std::max<int64_t>(0, max_buffered_steps_ - segment.steps()), actor_id,
      env_slot);
  if (absl::Status added = stitcher_.Add(std::move(segment)); !added.ok()) {
    Reject(actor_id, env_slot, added);
    return;
  }
  for (double r : returns) {
    recent_returns_.push_back(r);
    if (recent_returns_.size() > kRecentReturns) recent_returns_.pop_front();
  }
  unreported_.episodes += static_cast<int64_t>(returns.size());
  for (Rollout& rollout : stitcher_.TakeReady()) {
    pending_.push_back(std::move(rollout));
  }
}

void SegmentIntake::Reject(int64_t actor_id, int64_t env_slot,
                           const absl::Status& why) {
  ++unreported_.rejected;
  if (!first_rejection_.empty()) return;
  first_rejection_ =
      absl::StrCat("actor ", actor_id, " slot ", env_slot, ": ", why.message());
}

std::string SegmentIntake::TakeFirstRejection() {
  std::string first = std::move(first_rejection_);
  first_rejection_.clear();
  return first;
}

}  // namespace vantage
