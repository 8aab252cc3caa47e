#ifndef VANTAGE_PROTO_WIRE_FORMAT_H_
#define VANTAGE_PROTO_WIRE_FORMAT_H_

// Conversions between the in-memory types of common/ and the messages of
// proto/vantage.proto. They live here rather than in common/ so that common
// never depends on generated code.
//
// Decoding takes input from the network: every malformed message is an
// InvalidArgument error whose message names the field (for example
// "segment.rewards: 40 bytes for shape [11] float32, expected 44"), never a
// crash. Decoding checks only what the wire format itself promises (known
// dtypes, consistent byte counts, the dtypes each field must have); whether
// a segment fits the environment is ValidateSegment's business.

#include <ATen/core/Tensor.h>

#include <cstdint>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/env/environment.h"
#include "common/nn/policy_weights.h"
#include "common/rollout/segment.h"
#include "proto/vantage.pb.h"

namespace vantage {

// The call metadata entry that carries a registration's session (what
// RegisterResponse.session returned) on every stream and subscription.
inline constexpr char kSessionMetadataKey[] = "vantage-session";

// Supports float32, float64, int64, bool and uint8 tensors on any device and
// with any strides; other dtypes are a programmer error (c10::Error). An
// undefined tensor clears `proto`, which TensorFromProto refuses.
void TensorToProto(const at::Tensor& tensor, pb::Tensor* proto);

// A new contiguous CPU tensor holding a copy of the message's data. `field`
// prefixes every error message; the data may hold at most `max_bytes` bytes.
absl::StatusOr<at::Tensor> TensorFromProto(const pb::Tensor& proto,
                                           absl::string_view field,
                                           int64_t max_bytes);

// Undefined tensors of `segment` are left unset, and SegmentFromProto
// refuses unset tensors. `max_bytes` bounds each tensor separately.
void SegmentToProto(const Segment& segment, pb::Segment* proto);
absl::StatusOr<Segment> SegmentFromProto(const pb::Segment& proto,
                                         int64_t max_bytes);
// An upper bound on the serialised size of any segment of at most
// `max_steps` steps (and a recurrent state of `core_state_size` floats)
// that ValidateSegment accepts for `spec`: what a learner must be willing to
// read, and no more.
int64_t MaxSegmentMessageBytes(const EnvSpec& spec, int64_t max_steps,
                               int64_t core_state_size = 0);

// Weight tensors must be float32 or float64 (ImportPolicyWeights converts
// them to the policy's dtype). `max_bytes` bounds each tensor separately.
void WeightsToProto(const PolicyWeights& weights, pb::Weights* proto);
absl::StatusOr<PolicyWeights> WeightsFromProto(const pb::Weights& proto,
                                               int64_t max_bytes);

// How large a spec may be before anything is allocated for it: a learner's
// networks, normaliser and buffers grow with these sizes.
struct SpecLimits {
  int64_t max_name_bytes = 4096;  // mjcf:PATH names are paths
  int64_t max_observation_size = 1 << 16;
  int64_t max_action_size = 1 << 12;
  int64_t max_episode_steps = 100000000;
};

void EnvSpecToProto(const EnvSpec& spec, pb::EnvSpec* proto);
// Refuses specs no environment can have and specs beyond `limits`: an empty
// or too long name, sizes below 1 or above the limits, bounds that are not
// action_size (low < high, no NaN; an infinite bound means that side is
// unbounded) pairs when continuous or that are present when discrete, a
// time limit below 0 (0: none) or above the limit, a negative or
// non-finite control_dt.
absl::StatusOr<EnvSpec> EnvSpecFromProto(const pb::EnvSpec& proto,
                                         const SpecLimits& limits = {});

// OK if `got` equals `expected` in every field, else InvalidArgument naming
// the first field that differs, with both values.
absl::Status CheckSameSpec(const EnvSpec& expected, const EnvSpec& got);

}  // namespace vantage

#endif  // VANTAGE_PROTO_WIRE_FORMAT_H_
