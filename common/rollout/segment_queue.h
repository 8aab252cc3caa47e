#ifndef VANTAGE_COMMON_ROLLOUT_SEGMENT_QUEUE_H_
#define VANTAGE_COMMON_ROLLOUT_SEGMENT_QUEUE_H_

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "common/rollout/segment.h"

namespace vantage {

// Where the actor core puts segments: an in-process queue in local mode,
// a gRPC stream in distributed runs.
class SegmentSink {
 public:
  virtual ~SegmentSink() = default;
  // Blocks while the receiver is full (backpressure); Cancelled once closed.
  virtual absl::Status Send(Segment segment) = 0;
};

// Where the learner core takes them from.
class SegmentSource {
 public:
  virtual ~SegmentSource() = default;
  // Blocks until a segment arrives; Cancelled once closed and drained.
  virtual absl::StatusOr<Segment> Receive() = 0;
  // As Receive, but DeadlineExceeded once `timeout` passed without one
  // (a source that cannot wait less blocks as Receive does).
  virtual absl::StatusOr<Segment> ReceiveFor(absl::Duration timeout) {
    return Receive();
  }
  // Whether whoever filled it already checked every segment against the
  // run's spec and limits (the learner's gateway does, to answer its
  // sender), so that the receiver need not check them again.
  virtual bool checked() const { return false; }
};

// A bounded queue that is both: at most `capacity` segments wait, so actors
// that outpace the learner block instead of growing memory.
class SegmentQueue : public SegmentSink, public SegmentSource {
 public:
  // `checked`: what checked() says (segments filled in by a checking
  // sender only).
  explicit SegmentQueue(size_t capacity, bool checked = false);

  absl::Status Send(Segment segment) override;
  absl::StatusOr<Segment> Receive() override;
  absl::StatusOr<Segment> ReceiveFor(absl::Duration timeout) override;
  // Wakes every waiter; later Sends fail, Receives drain what is left.
  void Close();
  size_t size() const;
  bool checked() const override { return checked_; }

 private:
  const size_t capacity_;
  const bool checked_;
  mutable std::mutex mutex_;
  std::condition_variable not_full_;
  std::condition_variable not_empty_;
  std::deque<Segment> segments_;
  bool closed_ = false;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_ROLLOUT_SEGMENT_QUEUE_H_
