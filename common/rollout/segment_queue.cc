#include "common/rollout/segment_queue.h"

#include <utility>

namespace vantage {

SegmentQueue::SegmentQueue(size_t capacity, bool checked)
    : capacity_(capacity == 0 ? 1 : capacity), checked_(checked) {}

absl::Status SegmentQueue::Send(Segment segment) {
  std::unique_lock<std::mutex> lock(mutex_);
  not_full_.wait(lock, [&] { return closed_ || segments_.size() < capacity_; });
  if (closed_) return absl::CancelledError("segment queue closed");
  segments_.push_back(std::move(segment));
  not_empty_.notify_one();
  return absl::OkStatus();
}

absl::StatusOr<Segment> SegmentQueue::Receive() {
  return ReceiveFor(absl::InfiniteDuration());
}

absl::StatusOr<Segment> SegmentQueue::ReceiveFor(absl::Duration timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  auto ready = [&] { return closed_ || !segments_.empty(); };
  if (timeout == absl::InfiniteDuration()) {
    not_empty_.wait(lock, ready);
  } else if (!not_empty_.wait_for(lock, absl::ToChronoNanoseconds(timeout),
                                  ready)) {
    return absl::DeadlineExceededError("no segment arrived");
  }
  if (segments_.empty()) return absl::CancelledError("segment queue closed");
  Segment segment = std::move(segments_.front());
  segments_.pop_front();
  not_full_.notify_one();
  return segment;
}

void SegmentQueue::Close() {
  std::lock_guard<std::mutex> lock(mutex_);
  closed_ = true;
  not_full_.notify_all();
  not_empty_.notify_all();
}

size_t SegmentQueue::size() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return segments_.size();
}

}  // namespace vantage
