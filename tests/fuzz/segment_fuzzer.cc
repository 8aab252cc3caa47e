// Segment decoding and validation, as the learner's gateway does them for
// every message of a segment stream: bytes -> pb::Segment -> Segment ->
// ValidateSegment against the run's spec. A continuous and a discrete spec
// see every input. A segment that passes must survive a round trip
// through the wire format unchanged.

#include <ATen/ATen.h>

#include <cstddef>
#include <cstdint>

#include "absl/status/statusor.h"
#include "common/rollout/segment.h"
#include "proto/vantage.pb.h"
#include "proto/wire_format.h"
#include "tests/fuzz/fuzz_fixtures.h"

namespace vantage {
namespace {

bool SameTensor(const at::Tensor& a, const at::Tensor& b) {
  return a.scalar_type() == b.scalar_type() && a.sizes() == b.sizes() &&
         at::equal(a, b);
}

void CheckRoundTrip(const Segment& segment, const EnvSpec& spec,
                    int64_t max_bytes) {
  pb::Segment proto;
  SegmentToProto(segment, &proto);
  absl::StatusOr<Segment> again = SegmentFromProto(proto, max_bytes);
  if (!again.ok()) FuzzFail("a valid segment does not decode", again.status());
  const absl::Status valid = ValidateSegment(*again, spec, kFuzzMaxSteps);
  if (!valid.ok()) FuzzFail("a valid segment's copy is invalid", valid);
  if (again->actor_id != segment.actor_id ||
      again->env_slot != segment.env_slot ||
      again->sequence != segment.sequence ||
      again->policy_version != segment.policy_version ||
      !SameTensor(again->observations, segment.observations) ||
      !SameTensor(again->actions, segment.actions) ||
      !SameTensor(again->rewards, segment.rewards) ||
      !SameTensor(again->terminated, segment.terminated) ||
      !SameTensor(again->truncated, segment.truncated) ||
      !SameTensor(again->final_observations, segment.final_observations) ||
      !SameTensor(again->behaviour_log_probs, segment.behaviour_log_probs) ||
      again->episode_returns != segment.episode_returns ||
      again->episode_lengths != segment.episode_lengths) {
    FuzzFail("a valid segment changed in a round trip",
             absl::InternalError(""));
  }
}

}  // namespace
}  // namespace vantage

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  at::set_num_threads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vantage;
  pb::Segment proto;
  if (!proto.ParseFromArray(data, static_cast<int>(size))) return 0;
  for (const EnvSpec& spec : {FuzzContinuousSpec(), FuzzDiscreteSpec()}) {
    // What the gateway allows each tensor of this run.
    const int64_t max_bytes = MaxSegmentMessageBytes(spec, kFuzzMaxSteps);
    absl::StatusOr<Segment> segment = SegmentFromProto(proto, max_bytes);
    if (!segment.ok()) return 0;
    if (ValidateSegment(*segment, spec, kFuzzMaxSteps).ok()) {
      CheckRoundTrip(*segment, spec, max_bytes);
    }
  }
  return 0;
}
