#include "proto/wire_format.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/types/span.h"

// Payloads are the host's bytes copied as they are; a big-endian host would
// need a byte swap per element in both directions.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the wire format is little-endian");

namespace vantage {
namespace {

struct DTypeInfo {
  pb::Tensor::DType wire;
  at::ScalarType scalar;
  const char* name;
  int64_t itemsize;
};

constexpr DTypeInfo kDTypes[] = {
    {pb::Tensor::FLOAT32, at::kFloat, "float32", 4},
    {pb::Tensor::FLOAT64, at::kDouble, "float64", 8},
    {pb::Tensor::INT64, at::kLong, "int64", 8},
    {pb::Tensor::BOOL, at::kBool, "bool", 1},
    {pb::Tensor::UINT8, at::kByte, "uint8", 1},
};

// Takes an int because proto3 enums are open: a peer with a newer schema,
// or a corrupt one, can send any number.
const DTypeInfo* FindWire(int wire) {
  for (const DTypeInfo& info : kDTypes) {
    if (info.wire == wire) return &info;
  }
  return nullptr;
}

const DTypeInfo* FindScalar(at::ScalarType scalar) {
  for (const DTypeInfo& info : kDTypes) {
    if (info.scalar == scalar) return &info;
  }
  return nullptr;
}

std::string WireDTypeName(int wire) {
  if (const DTypeInfo* info = FindWire(wire)) return info->name;
  if (pb::Tensor::DType_IsValid(wire)) {
    return pb::Tensor::DType_Name(static_cast<pb::Tensor::DType>(wire));
  }
  return absl::StrCat(wire);
}

template <typename Sizes>
std::string ShapeString(const Sizes& shape) {
  return absl::StrCat("[", absl::StrJoin(shape, ", "), "]");
}

// Shortest text that parses back to the same double, so that two values
// reported as different never print alike.
std::string Num(double value) {
  char buffer[32];
  const std::to_chars_result result =
      std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

absl::Status Invalid(absl::string_view field, absl::string_view what) {
  return absl::InvalidArgumentError(absl::StrCat(field, ": ", what));
}

// Decodes a tensor field of a message, which must be present and have one
// of `dtypes`.
absl::StatusOr<at::Tensor> DecodeField(
    bool present, const pb::Tensor& proto, absl::string_view field,
    absl::Span<const pb::Tensor::DType> dtypes, int64_t max_bytes) {
  if (!present) return Invalid(field, "missing");
  // An unknown dtype is left to TensorFromProto, which says so.
  if (FindWire(proto.dtype()) != nullptr) {
    bool allowed = false;
    for (pb::Tensor::DType dtype : dtypes) allowed |= proto.dtype() == dtype;
    if (!allowed) {
      std::vector<std::string> names;
      for (pb::Tensor::DType dtype : dtypes) {
        names.push_back(WireDTypeName(dtype));
      }
      return Invalid(field,
                     absl::StrCat("dtype ", WireDTypeName(proto.dtype()),
                                  ", expected ", absl::StrJoin(names, " or ")));
    }
  }
  return TensorFromProto(proto, field, max_bytes);
}

absl::Status Differs(absl::string_view field, absl::string_view expected,
                     absl::string_view got) {
  return absl::InvalidArgumentError(absl::StrCat(
      "env spec differs in ", field, ": expected ", expected, ", got ", got));
}

absl::Status SameBounds(absl::string_view field,
                        const std::vector<double>& expected,
                        const std::vector<double>& got) {
  if (expected.size() != got.size()) {
    return Differs(field, absl::StrCat(expected.size(), " values"),
                   absl::StrCat(got.size()));
  }
  for (size_t i = 0; i < expected.size(); ++i) {
    if (expected[i] != got[i]) {
      return Differs(absl::StrCat(field, "[", i, "]"), Num(expected[i]),
                     Num(got[i]));
    }
  }
  return absl::OkStatus();
}

// A Dict observation's entries, bounded before anything is copied.
absl::Status CheckKeyLimits(const pb::EnvSpec& proto,
                            const SpecLimits& limits) {
  if (proto.observation_keys_size() > limits.max_observation_size) {
    return Invalid(
        "spec.observation_keys",
        absl::StrCat(proto.observation_keys_size(),
                     " entries, expected <= ", limits.max_observation_size));
  }
  for (int i = 0; i < proto.observation_keys_size(); ++i) {
    const pb::ObservationKey& key = proto.observation_keys(i);
    if (static_cast<int64_t>(key.name().size()) > limits.max_name_bytes ||
        key.shape_size() > 3) {
      return Invalid(
          absl::StrCat("spec.observation_keys[", i, "]"),
          absl::StrCat("a name of ", key.name().size(), " bytes and ",
                       key.shape_size(), " dimensions, expected at most ",
                       limits.max_name_bytes, " and 3"));
    }
  }
  return absl::OkStatus();
}

std::string KeyText(const ObservationKey& key) {
  return absl::StrCat(
      "\"", key.name, "\" of ",
      key.image() ? absl::StrCat("uint8 ", absl::StrJoin(key.shape, "x"),
                                 " (high ", key.high, ")")
                  : absl::StrCat(key.size, " values"));
}

absl::Status SameKeys(const std::vector<ObservationKey>& expected,
                      const std::vector<ObservationKey>& got) {
  if (expected.size() != got.size()) {
    return Differs("observation_keys",
                   absl::StrCat(expected.size(), " entries"),
                   absl::StrCat(got.size()));
  }
  for (size_t i = 0; i < expected.size(); ++i) {
    const ObservationKey& a = expected[i];
    const ObservationKey& b = got[i];
    if (a.name != b.name || a.size != b.size || a.shape != b.shape ||
        a.high != b.high) {
      return Differs(absl::StrCat("observation_keys[", i, "]"), KeyText(a),
                     KeyText(b));
    }
  }
  return absl::OkStatus();
}

}  // namespace

void TensorToProto(const at::Tensor& tensor, pb::Tensor* proto) {
  proto->Clear();
  if (!tensor.defined()) return;
  const DTypeInfo* info = FindScalar(tensor.scalar_type());
  TORCH_CHECK(info != nullptr && tensor.layout() == at::kStrided,
              "TensorToProto: no wire format for a ", tensor.layout(), " ",
              tensor.scalar_type(), " tensor");
  // A view's elements are not one row-major run of its storage, and the
  // payload must be.
  const at::Tensor dense = tensor.cpu().contiguous();
  proto->set_dtype(info->wire);
  proto->mutable_shape()->Reserve(static_cast<int>(dense.dim()));
  for (int64_t size : dense.sizes()) proto->add_shape(size);
  if (dense.nbytes() > 0) {
    proto->mutable_data()->assign(static_cast<const char*>(dense.data_ptr()),
                                  dense.nbytes());
  }
}

absl::StatusOr<at::Tensor> TensorFromProto(const pb::Tensor& proto,
                                           absl::string_view field,
                                           int64_t max_bytes) {
  const DTypeInfo* info = FindWire(proto.dtype());
  if (info == nullptr) {
    return Invalid(
        field, absl::StrCat("unknown dtype ", WireDTypeName(proto.dtype())));
  }
  const std::vector<int64_t> shape(proto.shape().begin(), proto.shape().end());
  // Zero dimensions count as one here so that no shape reaches at::empty
  // whose strides would overflow, even one with no elements.
  int64_t span = info->itemsize;
  bool empty = false;
  for (size_t i = 0; i < shape.size(); ++i) {
    if (shape[i] < 0) {
      return Invalid(field, absl::StrCat("dimension ", i, " of shape ",
                                         ShapeString(shape), " is negative"));
    }
    empty |= shape[i] == 0;
    if (__builtin_mul_overflow(span, shape[i] == 0 ? 1 : shape[i], &span)) {
      return Invalid(field,
                     absl::StrCat("shape ", ShapeString(shape), " ", info->name,
                                  " overflows a 64-bit byte count"));
    }
  }
  const int64_t bytes = empty ? 0 : span;
  const std::string& data = proto.data();
  if (data.size() != static_cast<uint64_t>(bytes)) {
    return Invalid(field, absl::StrCat(data.size(), " bytes for shape ",
                                       ShapeString(shape), " ", info->name,
                                       ", expected ", bytes));
  }
  if (bytes > max_bytes) {
    return Invalid(
        field, absl::StrCat(bytes, " bytes exceed the limit of ", max_bytes));
  }
  // Any other byte in a bool tensor is undefined behaviour in LibTorch.
  if (info->scalar == at::kBool) {
    for (size_t i = 0; i < data.size(); ++i) {
      const auto byte = static_cast<unsigned char>(data[i]);
      if (byte > 1) {
        return Invalid(
            field, absl::StrCat("bool element ", i, " is byte ",
                                static_cast<int>(byte), ", expected 0 or 1"));
      }
    }
  }
  at::Tensor tensor = at::empty(shape, at::TensorOptions().dtype(info->scalar));
  if (bytes > 0) std::memcpy(tensor.data_ptr(), data.data(), data.size());
  return tensor;
}

void SegmentToProto(const Segment& segment, pb::Segment* proto) {
  proto->Clear();
  proto->set_actor_id(segment.actor_id);
  proto->set_env_slot(segment.env_slot);
  proto->set_sequence(segment.sequence);
  proto->set_policy_version(segment.policy_version);
  // mutable_x() marks x present, so undefined tensors must not reach it.
  if (segment.observations.defined()) {
    TensorToProto(segment.observations, proto->mutable_observations());
  }
  if (segment.actions.defined()) {
    TensorToProto(segment.actions, proto->mutable_actions());
  }
  if (segment.rewards.defined()) {
    TensorToProto(segment.rewards, proto->mutable_rewards());
  }
  if (segment.terminated.defined()) {
    TensorToProto(segment.terminated, proto->mutable_terminated());
  }
  if (segment.truncated.defined()) {
    TensorToProto(segment.truncated, proto->mutable_truncated());
  }
  if (segment.final_observations.defined()) {
    TensorToProto(segment.final_observations,
                  proto->mutable_final_observations());
  }
  if (segment.behaviour_log_probs.defined()) {
    TensorToProto(segment.behaviour_log_probs,
                  proto->mutable_behaviour_log_probs());
  }
  if (segment.core_state.defined()) {
    TensorToProto(segment.core_state, proto->mutable_core_state());
  }
  if (segment.action_masks.defined()) {
    TensorToProto(segment.action_masks, proto->mutable_action_masks());
  }
  proto->mutable_episode_returns()->Add(segment.episode_returns.begin(),
                                        segment.episode_returns.end());
  proto->mutable_episode_lengths()->Add(segment.episode_lengths.begin(),
                                        segment.episode_lengths.end());
  proto->set_first_episode_step(segment.first_episode_step);
}

absl::StatusOr<Segment> SegmentFromProto(const pb::Segment& proto,
                                         int64_t max_bytes) {
  Segment segment;
  segment.actor_id = proto.actor_id();
  segment.env_slot = proto.env_slot();
  segment.sequence = proto.sequence();
  segment.policy_version = proto.policy_version();
  struct Field {
    bool present;
    const pb::Tensor& proto;
    const char* name;
    absl::Span<const pb::Tensor::DType> dtypes;
    at::Tensor* out;
  };
  static constexpr pb::Tensor::DType kFloat[] = {pb::Tensor::FLOAT32};
  static constexpr pb::Tensor::DType kBool[] = {pb::Tensor::BOOL};
  // Which of the two the run's spec wants is ValidateSegment's check.
  static constexpr pb::Tensor::DType kObservation[] = {pb::Tensor::FLOAT32,
                                                       pb::Tensor::UINT8};
  const Field fields[] = {
      {proto.has_observations(), proto.observations(), "segment.observations",
       kObservation, &segment.observations},
      {proto.has_actions(), proto.actions(), "segment.actions", kFloat,
       &segment.actions},
      {proto.has_rewards(), proto.rewards(), "segment.rewards", kFloat,
       &segment.rewards},
      {proto.has_terminated(), proto.terminated(), "segment.terminated", kBool,
       &segment.terminated},
      {proto.has_truncated(), proto.truncated(), "segment.truncated", kBool,
       &segment.truncated},
      {proto.has_final_observations(), proto.final_observations(),
       "segment.final_observations", kObservation, &segment.final_observations},
      {proto.has_behaviour_log_probs(), proto.behaviour_log_probs(),
       "segment.behaviour_log_probs", kFloat, &segment.behaviour_log_probs},
  };
  for (const Field& field : fields) {
    absl::StatusOr<at::Tensor> tensor = DecodeField(
        field.present, field.proto, field.name, field.dtypes, max_bytes);
    if (!tensor.ok()) return tensor.status();
    *field.out = *std::move(tensor);
  }
  // Optional: only a recurrent policy's segments carry it.
  if (proto.has_core_state()) {
    absl::StatusOr<at::Tensor> state = DecodeField(
        true, proto.core_state(), "segment.core_state", kFloat, max_bytes);
    if (!state.ok()) return state.status();
    segment.core_state = *std::move(state);
  }
  // Optional: only masked discrete actions' segments carry them.
  if (proto.has_action_masks()) {
    absl::StatusOr<at::Tensor> masks = DecodeField(
        true, proto.action_masks(), "segment.action_masks", kBool, max_bytes);
    if (!masks.ok()) return masks.status();
    segment.action_masks = *std::move(masks);
  }
  segment.episode_returns.assign(proto.episode_returns().begin(),
                                 proto.episode_returns().end());
  segment.episode_lengths.assign(proto.episode_lengths().begin(),
                                 proto.episode_lengths().end());
  segment.first_episode_step = proto.first_episode_step();
  return segment;
}

int64_t MaxSegmentMessageBytes(const EnvSpec& spec, int64_t max_steps,
                               int64_t core_state_size) {
  const int64_t t = std::max<int64_t>(1, max_steps);
  const int64_t act = spec.action_width();
  // observations [T+1, obs] and at most T final observations, float32 or
  // uint8; actions [T, act], rewards and log-probs [T] float32; two bool
  // [T] and masked actions' bool [T, actions]; at most T episodes of a double
  // and a varint (<= 10 bytes) each.
  const int64_t observation_bytes = spec.byte_observations() ? 1 : 4;
  const int64_t payload =
      observation_bytes * spec.observation_size * (2 * t + 1) + 4 * act * t +
      8 * t + 2 * t + 18 * t + 4 * core_state_size +
      (spec.action_masks ? spec.action_size * t : 0);
  // Tags, lengths, shapes and the four integers, generously.
  constexpr int64_t kFraming = 4096;
  return payload + kFraming;
}

void WeightsToProto(const PolicyWeights& weights, pb::Weights* proto) {
  proto->Clear();
  proto->set_version(weights.version);
  proto->mutable_parameters()->Reserve(
      static_cast<int>(weights.parameters.size()));
  for (const at::Tensor& parameter : weights.parameters) {
    TensorToProto(parameter, proto->add_parameters());
  }
  proto->set_normalizer_count(weights.normalizer_count);
  if (weights.normalizer_mean.defined()) {
    TensorToProto(weights.normalizer_mean, proto->mutable_normalizer_mean());
  }
  if (weights.normalizer_var.defined()) {
    TensorToProto(weights.normalizer_var, proto->mutable_normalizer_var());
  }
}

absl::StatusOr<PolicyWeights> WeightsFromProto(const pb::Weights& proto,
                                               int64_t max_bytes) {
  constexpr pb::Tensor::DType kFloating[] = {pb::Tensor::FLOAT32,
                                             pb::Tensor::FLOAT64};
  PolicyWeights weights;
  weights.version = proto.version();
  weights.parameters.reserve(proto.parameters_size());
  for (int i = 0; i < proto.parameters_size(); ++i) {
    absl::StatusOr<at::Tensor> parameter = DecodeField(
        true, proto.parameters(i), absl::StrCat("weights.parameters[", i, "]"),
        kFloating, max_bytes);
    if (!parameter.ok()) return parameter.status();
    weights.parameters.push_back(*std::move(parameter));
  }
  weights.normalizer_count = proto.normalizer_count();
  absl::StatusOr<at::Tensor> mean =
      DecodeField(proto.has_normalizer_mean(), proto.normalizer_mean(),
                  "weights.normalizer_mean", kFloating, max_bytes);
  if (!mean.ok()) return mean.status();
  weights.normalizer_mean = *std::move(mean);
  absl::StatusOr<at::Tensor> var =
      DecodeField(proto.has_normalizer_var(), proto.normalizer_var(),
                  "weights.normalizer_var", kFloating, max_bytes);
  if (!var.ok()) return var.status();
  weights.normalizer_var = *std::move(var);
  return weights;
}

void EnvSpecToProto(const EnvSpec& spec, pb::EnvSpec* proto) {
  proto->Clear();
  proto->set_name(spec.name);
  proto->set_observation_size(spec.observation_size);
  proto->set_discrete(spec.discrete);
  proto->set_action_size(spec.action_size);
  proto->mutable_action_low()->Add(spec.action_low.begin(),
                                   spec.action_low.end());
  proto->mutable_action_high()->Add(spec.action_high.begin(),
                                    spec.action_high.end());
  proto->set_max_episode_steps(spec.max_episode_steps);
  proto->set_control_dt(spec.control_dt);
  proto->mutable_observation_shape()->Add(spec.observation_shape.begin(),
                                          spec.observation_shape.end());
  proto->set_observation_high(spec.observation_high);
  proto->set_action_masks(spec.action_masks);
  proto->mutable_action_nvec()->Add(spec.action_nvec.begin(),
                                    spec.action_nvec.end());
  for (const ObservationKey& key : spec.observation_keys) {
    pb::ObservationKey* entry = proto->add_observation_keys();
    entry->set_name(key.name);
    entry->set_size(key.size);
    entry->mutable_shape()->Add(key.shape.begin(), key.shape.end());
    entry->set_high(key.high);
  }
}

absl::StatusOr<EnvSpec> EnvSpecFromProto(const pb::EnvSpec& proto,
                                         const SpecLimits& limits) {
  // Checked before anything is copied out of the message.
  if (static_cast<int64_t>(proto.name().size()) > limits.max_name_bytes) {
    return Invalid("spec.name", absl::StrCat(proto.name().size(),
                                             " bytes, expected at most ",
                                             limits.max_name_bytes));
  }
  if (proto.observation_size() > limits.max_observation_size) {
    return Invalid("spec.observation_size",
                   absl::StrCat(proto.observation_size(),
                                ", expected <= ", limits.max_observation_size));
  }
  if (proto.action_size() > limits.max_action_size) {
    return Invalid("spec.action_size",
                   absl::StrCat(proto.action_size(),
                                ", expected <= ", limits.max_action_size));
  }
  if (proto.max_episode_steps() > limits.max_episode_steps) {
    return Invalid("spec.max_episode_steps",
                   absl::StrCat(proto.max_episode_steps(),
                                ", expected <= ", limits.max_episode_steps));
  }
  if (proto.action_nvec_size() > limits.max_action_size) {
    return Invalid("spec.action_nvec", absl::StrCat(proto.action_nvec_size(),
                                                    " values, expected <= ",
                                                    limits.max_action_size));
  }
  if (absl::Status status = CheckKeyLimits(proto, limits); !status.ok()) {
    return status;
  }
  if (proto.observation_shape_size() > 3) {
    return Invalid("spec.observation_shape",
                   absl::StrCat(proto.observation_shape_size(),
                                " dimensions, expected none or 3"));
  }
  EnvSpec spec;
  spec.name = proto.name();
  spec.observation_size = proto.observation_size();
  spec.discrete = proto.discrete();
  spec.action_size = proto.action_size();
  spec.action_low.assign(proto.action_low().begin(), proto.action_low().end());
  spec.action_high.assign(proto.action_high().begin(),
                          proto.action_high().end());
  spec.max_episode_steps = proto.max_episode_steps();
  spec.control_dt = proto.control_dt();
  spec.observation_shape.assign(proto.observation_shape().begin(),
                                proto.observation_shape().end());
  spec.observation_high = proto.observation_high();
  spec.action_masks = proto.action_masks();
  spec.action_nvec.assign(proto.action_nvec().begin(),
                          proto.action_nvec().end());
  for (const pb::ObservationKey& entry : proto.observation_keys()) {
    spec.observation_keys.push_back(
        {entry.name(), entry.size(),
         std::vector<int64_t>(entry.shape().begin(), entry.shape().end()),
         entry.high()});
  }

  if (spec.name.empty()) return Invalid("spec.name", "empty");
  if (spec.observation_size < 1) {
    return Invalid("spec.observation_size",
                   absl::StrCat(spec.observation_size, ", expected >= 1"));
  }
  if (absl::Status status = CheckObservationLayout(spec); !status.ok()) {
    return status;
  }
  if (spec.action_size < 1) {
    return Invalid("spec.action_size",
                   absl::StrCat(spec.action_size, ", expected >= 1"));
  }
  if (absl::Status status = CheckActionLayout(spec); !status.ok()) {
    return status;
  }
  if (spec.action_masks && !spec.discrete) {
    return Invalid("spec.action_masks",
                   "true for continuous actions, which take no masks");
  }
  // A continuous action space has one [low, high] per dimension; a discrete
  // one has none, and bounds there would mean the sender got the kind wrong.
  const size_t bounds = spec.discrete ? 0 : spec.action_size;
  if (spec.action_low.size() != bounds) {
    return Invalid("spec.action_low",
                   absl::StrCat(spec.action_low.size(), " values, expected ",
                                bounds, " for ", spec.ActionString()));
  }
  if (spec.action_high.size() != bounds) {
    return Invalid("spec.action_high",
                   absl::StrCat(spec.action_high.size(), " values, expected ",
                                bounds, " for ", spec.ActionString()));
  }
  for (size_t i = 0; i < bounds; ++i) {
    const double low = spec.action_low[i];
    const double high = spec.action_high[i];
    // Also refuses NaN in either bound.
    if (!(low < high)) {
      return Invalid(absl::StrCat("spec.action_low[", i, "]"),
                     absl::StrCat(Num(low), " with action_high[", i, "] ",
                                  Num(high), ", expected low < high"));
    }
  }
  if (spec.max_episode_steps < 0) {
    return Invalid("spec.max_episode_steps",
                   absl::StrCat(spec.max_episode_steps, ", expected >= 0"));
  }
  if (!std::isfinite(spec.control_dt) || spec.control_dt < 0) {
    return Invalid("spec.control_dt",
                   absl::StrCat(Num(spec.control_dt), ", expected >= 0"));
  }
  return spec;
}

absl::Status CheckSameSpec(const EnvSpec& expected, const EnvSpec& got) {
  if (expected.name != got.name) {
    return Differs("name", absl::StrCat("\"", expected.name, "\""),
                   absl::StrCat("\"", got.name, "\""));
  }
  if (expected.observation_size != got.observation_size) {
    return Differs("observation_size", absl::StrCat(expected.observation_size),
                   absl::StrCat(got.observation_size));
  }
  if (expected.observation_shape != got.observation_shape) {
    const auto text = [](const std::vector<int64_t>& shape) {
      return shape.empty() ? std::string("none") : absl::StrJoin(shape, "x");
    };
    return Differs("observation_shape", text(expected.observation_shape),
                   text(got.observation_shape));
  }
  if (absl::Status status =
          SameKeys(expected.observation_keys, got.observation_keys);
      !status.ok()) {
    return status;
  }
  if (expected.observation_high != got.observation_high) {
    return Differs("observation_high", absl::StrCat(expected.observation_high),
                   absl::StrCat(got.observation_high));
  }
  if (expected.discrete != got.discrete) {
    return Differs("discrete", expected.discrete ? "true" : "false",
                   got.discrete ? "true" : "false");
  }
  if (expected.action_size != got.action_size) {
    return Differs("action_size", absl::StrCat(expected.action_size),
                   absl::StrCat(got.action_size));
  }
  if (expected.action_nvec != got.action_nvec) {
    const auto text = [](const std::vector<int64_t>& nvec) {
      return nvec.empty() ? std::string("none") : absl::StrJoin(nvec, "x");
    };
    return Differs("action_nvec", text(expected.action_nvec),
                   text(got.action_nvec));
  }
  if (expected.action_masks != got.action_masks) {
    return Differs("action_masks", expected.action_masks ? "true" : "false",
                   got.action_masks ? "true" : "false");
  }
  if (absl::Status status =
          SameBounds("action_low", expected.action_low, got.action_low);
      !status.ok()) {
    return status;
  }
  if (absl::Status status =
          SameBounds("action_high", expected.action_high, got.action_high);
      !status.ok()) {
    return status;
  }
  if (expected.max_episode_steps != got.max_episode_steps) {
    return Differs("max_episode_steps",
                   absl::StrCat(expected.max_episode_steps),
                   absl::StrCat(got.max_episode_steps));
  }
  if (expected.control_dt != got.control_dt) {
    return Differs("control_dt", Num(expected.control_dt), Num(got.control_dt));
  }
  return absl::OkStatus();
}

}  // namespace vantage
