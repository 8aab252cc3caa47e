#include "proto/wire_format.h"

#include <ATen/ATen.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "absl/strings/str_cat.h"
#include "common/nn/networks.h"
#include "common/nn/running_mean_std.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fakes/bit_equal.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

constexpr int64_t kNoLimit = std::numeric_limits<int64_t>::max();

template <typename Bits>
at::Tensor FromBits(const std::vector<Bits>& bits, at::ScalarType dtype) {
  at::Tensor t = at::empty({static_cast<int64_t>(bits.size())}, dtype);
  std::memcpy(t.data_ptr(), bits.data(), bits.size() * sizeof(Bits));
  return t;
}

at::Tensor RoundTrip(const at::Tensor& t) {
  pb::Tensor proto;
  TensorToProto(t, &proto);
  absl::StatusOr<at::Tensor> back = TensorFromProto(proto, "t", kNoLimit);
  EXPECT_TRUE(back.ok()) << back.status();
  return back.ok() ? *back : at::Tensor();
}

pb::Tensor Proto(pb::Tensor::DType dtype, std::vector<int64_t> shape,
                 size_t bytes) {
  pb::Tensor proto;
  proto.set_dtype(dtype);
  for (int64_t size : shape) proto.add_shape(size);
  proto.set_data(std::string(bytes, '\0'));
  return proto;
}

std::string Error(const pb::Tensor& proto, int64_t max_bytes = kNoLimit) {
  absl::StatusOr<at::Tensor> t = TensorFromProto(proto, "x.y", max_bytes);
  EXPECT_FALSE(t.ok());
  EXPECT_TRUE(t.ok() || absl::IsInvalidArgument(t.status())) << t.status();
  return std::string(t.status().message());
}

TEST(TensorWireTest, EveryDtypeRoundTripsBitExact) {
  const std::vector<at::Tensor> tensors = {
      // NaN with a payload, both zeros, both infinities, a denormal.
      FromBits<uint32_t>({0x7fc00001, 0xffc12345, 0x00000000, 0x80000000,
                          0x7f800000, 0xff800000, 0x00000001, 0x3f800000},
                         at::kFloat)
          .reshape({2, 4}),
      FromBits<uint64_t>(
          {0x7ff8000000000123, 0x8000000000000000, 0x0000000000000001,
           0xfff0000000000000, 0x3fb999999999999a},
          at::kDouble),
      at::tensor({std::numeric_limits<int64_t>::min(), int64_t{-1}, int64_t{0},
                  std::numeric_limits<int64_t>::max()},
                 at::kLong)
          .reshape({2, 1, 2}),
      at::tensor({1, 0, 0, 1, 1}, at::kLong).to(at::kBool),
      at::arange(256, at::kLong).to(at::kByte).reshape({16, 16}),
      at::scalar_tensor(2.5, at::kDouble),
      at::zeros({0, 17}, at::kFloat),
      at::zeros({3, 0, 2}, at::kBool),
  };
  for (const at::Tensor& t : tensors) {
    SCOPED_TRACE(::testing::Message() << t.scalar_type() << t.sizes());
    const at::Tensor back = RoundTrip(t);
    EXPECT_TRUE(BitEqual(t, back));
    EXPECT_TRUE(back.is_contiguous());
  }
}

TEST(TensorWireTest, PayloadIsRowMajorLittleEndian) {
  pb::Tensor proto;
  TensorToProto(at::tensor({1.0f, -2.0f}), &proto);
  EXPECT_EQ(proto.dtype(), pb::Tensor::FLOAT32);
  EXPECT_THAT(proto.shape(), ::testing::ElementsAre(2));
  EXPECT_EQ(proto.data(), std::string("\x00\x00\x80\x3f\x00\x00\x00\xc0", 8));

  TensorToProto(at::tensor({int64_t{1}, int64_t{2}, int64_t{256}, int64_t{-1}})
                    .reshape({2, 2}),
                &proto);
  EXPECT_EQ(proto.dtype(), pb::Tensor::INT64);
  EXPECT_THAT(proto.shape(), ::testing::ElementsAre(2, 2));
  EXPECT_EQ(proto.data(), std::string("\x01\0\0\0\0\0\0\0"
                                      "\x02\0\0\0\0\0\0\0"
                                      "\x00\x01\0\0\0\0\0\0"
                                      "\xff\xff\xff\xff\xff\xff\xff\xff",
                                      32));
}

TEST(TensorWireTest, NonContiguousTensorsAreEncodedInLogicalOrder) {
  const at::Tensor base = at::arange(24, at::kFloat).reshape({4, 6});
  const std::vector<at::Tensor> views = {
      base.t(),
      base.slice(/*dim=*/1, /*start=*/1, /*end=*/6, /*step=*/2),
      base.narrow(/*dim=*/0, /*start=*/1, /*length=*/2),     // storage offset
      at::arange(3, at::kLong).unsqueeze(0).expand({4, 3}),  // stride 0
      (base > 11).t(),
      base.select(/*dim=*/1, /*index=*/5),
  };
  for (const at::Tensor& view : views) {
    SCOPED_TRACE(::testing::Message() << view.sizes() << view.strides());
    const at::Tensor back = RoundTrip(view);
    EXPECT_TRUE(BitEqual(view.contiguous(), back));
    EXPECT_TRUE(at::equal(view, back));
  }
  pb::Tensor from_view;
  pb::Tensor from_copy;
  TensorToProto(base.t(), &from_view);
  TensorToProto(base.t().contiguous(), &from_copy);
  EXPECT_EQ(from_view.SerializeAsString(), from_copy.SerializeAsString());
}

TEST(TensorWireTest, RefusesUnknownDtypes) {
  EXPECT_EQ(Error(Proto(pb::Tensor::DTYPE_UNSPECIFIED, {1}, 4)),
            "x.y: unknown dtype DTYPE_UNSPECIFIED");
  EXPECT_EQ(Error(Proto(static_cast<pb::Tensor::DType>(42), {1}, 4)),
            "x.y: unknown dtype 42");
}

TEST(TensorWireTest, RefusesNegativeDimensions) {
  EXPECT_EQ(Error(Proto(pb::Tensor::FLOAT32, {3, -1}, 0)),
            "x.y: dimension 1 of shape [3, -1] is negative");
  EXPECT_EQ(Error(Proto(pb::Tensor::UINT8, {0, -5}, 0)),
            "x.y: dimension 1 of shape [0, -5] is negative");
}

TEST(TensorWireTest, RefusesByteCountsOffByOne) {
  EXPECT_EQ(Error(Proto(pb::Tensor::FLOAT32, {11}, 40)),
            "x.y: 40 bytes for shape [11] float32, expected 44");
  EXPECT_EQ(Error(Proto(pb::Tensor::FLOAT32, {11}, 45)),
            "x.y: 45 bytes for shape [11] float32, expected 44");
  EXPECT_EQ(Error(Proto(pb::Tensor::FLOAT64, {2, 3}, 47)),
            "x.y: 47 bytes for shape [2, 3] float64, expected 48");
  EXPECT_EQ(Error(Proto(pb::Tensor::INT64, {}, 9)),
            "x.y: 9 bytes for shape [] int64, expected 8");
  EXPECT_EQ(Error(Proto(pb::Tensor::BOOL, {0, 4}, 1)),
            "x.y: 1 bytes for shape [0, 4] bool, expected 0");
  EXPECT_TRUE(
      TensorFromProto(Proto(pb::Tensor::FLOAT32, {11}, 44), "x.y", 44).ok());
}

TEST(TensorWireTest, RefusesShapesWhoseSizeOverflows) {
  constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
  // The element count itself overflows.
  EXPECT_THAT(
      Error(Proto(pb::Tensor::UINT8, {int64_t{1} << 32, int64_t{1} << 32}, 0)),
      HasSubstr("x.y: shape [4294967296, 4294967296] uint8 overflows"));
  EXPECT_THAT(Error(Proto(pb::Tensor::BOOL, {kMax, 2}, 0)),
              HasSubstr("overflows"));
  // The count fits, the byte count does not.
  EXPECT_THAT(Error(Proto(pb::Tensor::FLOAT64, {int64_t{1} << 61}, 0)),
              HasSubstr("x.y: shape [2305843009213693952] float64 overflows"));
  // No elements, but strides that would overflow.
  EXPECT_THAT(Error(Proto(pb::Tensor::FLOAT32, {0, kMax, kMax}, 0)),
              HasSubstr("overflows"));
  // Large but representable: an honest byte-count mismatch.
  EXPECT_EQ(Error(Proto(pb::Tensor::FLOAT32, {int64_t{1} << 40}, 0)),
            "x.y: 0 bytes for shape [1099511627776] float32, expected "
            "4398046511104");
}

TEST(TensorWireTest, RefusesDataOverTheLimit) {
  const pb::Tensor proto = Proto(pb::Tensor::FLOAT32, {11}, 44);
  EXPECT_EQ(Error(proto, 43), "x.y: 44 bytes exceed the limit of 43");
  EXPECT_TRUE(TensorFromProto(proto, "x.y", 44).ok());
  EXPECT_TRUE(
      TensorFromProto(Proto(pb::Tensor::FLOAT32, {0}, 0), "x.y", 0).ok());
}

TEST(TensorWireTest, RefusesBoolBytesOtherThanZeroOrOne) {
  pb::Tensor proto = Proto(pb::Tensor::BOOL, {4}, 4);
  proto.set_data(std::string("\x01\x00\x02\x01", 4));
  EXPECT_EQ(Error(proto), "x.y: bool element 2 is byte 2, expected 0 or 1");
}

TEST(TensorWireTest, UndefinedTensorEncodesAsUnspecified) {
  pb::Tensor proto = Proto(pb::Tensor::FLOAT32, {1}, 4);
  TensorToProto(at::Tensor(), &proto);
  EXPECT_EQ(proto.dtype(), pb::Tensor::DTYPE_UNSPECIFIED);
  EXPECT_EQ(proto.shape_size(), 0);
  EXPECT_TRUE(proto.data().empty());
}

TEST(TensorWireTest, UnsupportedDtypeIsAProgrammerError) {
  pb::Tensor proto;
  EXPECT_THROW(TensorToProto(at::zeros({2}, at::kHalf), &proto), c10::Error);
  EXPECT_THROW(TensorToProto(at::zeros({2}, at::kInt), &proto), c10::Error);
}

// The contract later code relies on: which calls stream, and that the large
// numeric lists are packed.
TEST(ProtoContractTest, LearnerServiceAndPackedFields) {
  const google::protobuf::ServiceDescriptor* service =
      pb::Segment::descriptor()->file()->FindServiceByName("Learner");
  ASSERT_NE(service, nullptr);
  EXPECT_EQ(service->full_name(), "vantage.pb.Learner");
  ASSERT_EQ(service->method_count(), 4);
  struct Method {
    const char* name;
    bool client_streaming;
    bool server_streaming;
  };
  for (const Method& m :
       {Method{"Register", false, false}, Method{"StreamSegments", true, false},
        Method{"SubscribeWeights", false, true},
        Method{"GetWeights", false, false}}) {
    const google::protobuf::MethodDescriptor* method =
        service->FindMethodByName(m.name);
    ASSERT_NE(method, nullptr) << m.name;
    EXPECT_EQ(method->client_streaming(), m.client_streaming) << m.name;
    EXPECT_EQ(method->server_streaming(), m.server_streaming) << m.name;
  }
  EXPECT_TRUE(pb::Tensor::descriptor()->FindFieldByName("shape")->is_packed());
  for (const char* name : {"episode_returns", "episode_lengths"}) {
    EXPECT_TRUE(pb::Segment::descriptor()->FindFieldByName(name)->is_packed());
  }
  for (const char* name : {"action_low", "action_high"}) {
    EXPECT_TRUE(pb::EnvSpec::descriptor()->FindFieldByName(name)->is_packed());
  }
}

EnvSpec ContinuousSpec() {
  EnvSpec spec;
  spec.name = "HalfCheetah";
  spec.observation_size = 17;
  spec.action_size = 6;
  spec.action_low.assign(6, -1.0);
  spec.action_high.assign(6, 1.0);
  spec.max_episode_steps = 1000;
  spec.control_dt = 0.05;
  return spec;
}

// 16 steps of a 17-observation, 6-action environment with one truncation,
// one termination and values of every sign and magnitude.
Segment RealisticSegment() {
  at::manual_seed(7);
  constexpr int64_t kSteps = 16;
  Segment s;
  s.actor_id = 3;
  s.env_slot = 5;
  s.sequence = 123456789012;
  s.policy_version = 41;
  s.observations = at::randn({kSteps + 1, 17}) * 10;
  s.actions = at::rand({kSteps, 6}) * 2 - 1;
  s.rewards = at::randn({kSteps});
  s.terminated = at::zeros({kSteps}, at::kBool);
  s.terminated[11] = true;
  s.truncated = at::zeros({kSteps}, at::kBool);
  s.truncated[4] = true;
  s.final_observations = at::randn({1, 17});
  s.behaviour_log_probs = -at::rand({kSteps}) * 5;
  s.episode_returns = {-0.1, 1234.5678};
  s.episode_lengths = {1000, 7};
  s.first_episode_step = 988;
  return s;
}

void ExpectSameSegment(const Segment& a, const Segment& b) {
  EXPECT_EQ(a.actor_id, b.actor_id);
  EXPECT_EQ(a.env_slot, b.env_slot);
  EXPECT_EQ(a.sequence, b.sequence);
  EXPECT_EQ(a.policy_version, b.policy_version);
  EXPECT_TRUE(BitEqual(a.observations, b.observations));
  EXPECT_TRUE(BitEqual(a.actions, b.actions));
  EXPECT_TRUE(BitEqual(a.rewards, b.rewards));
  EXPECT_TRUE(BitEqual(a.terminated, b.terminated));
  EXPECT_TRUE(BitEqual(a.truncated, b.truncated));
  EXPECT_TRUE(BitEqual(a.final_observations, b.final_observations));
  EXPECT_TRUE(BitEqual(a.behaviour_log_probs, b.behaviour_log_probs));
  EXPECT_EQ(a.episode_returns, b.episode_returns);
  EXPECT_EQ(a.episode_lengths, b.episode_lengths);
  EXPECT_EQ(a.first_episode_step, b.first_episode_step);
}

// Through the serialized bytes, as over the network.
absl::StatusOr<Segment> SegmentOverWire(const Segment& segment,
                                        int64_t max_bytes = kNoLimit) {
  pb::Segment proto;
  SegmentToProto(segment, &proto);
  pb::Segment received;
  EXPECT_TRUE(received.ParseFromString(proto.SerializeAsString()));
  return SegmentFromProto(received, max_bytes);
}

TEST(SegmentWireTest, RoundTripsBitExact) {
  const Segment segment = RealisticSegment();
  ASSERT_TRUE(ValidateSegment(segment, ContinuousSpec(), 2048).ok());
  absl::StatusOr<Segment> back = SegmentOverWire(segment);
  ASSERT_TRUE(back.ok()) << back.status();
  ExpectSameSegment(segment, *back);
  EXPECT_TRUE(ValidateSegment(*back, ContinuousSpec(), 2048).ok());
}

// A recurrent policy's start state travels bit for bit; a segment of a
// feed-forward policy (or an actor from before states) has none, and a
// state of the wrong dtype is refused by name.
TEST(SegmentWireTest, ACoreStateRoundTripsAndIsOptional) {
  Segment segment = RealisticSegment();
  absl::StatusOr<Segment> back = SegmentOverWire(segment);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_FALSE(back->core_state.defined());
  segment.core_state = at::randn({48});
  back = SegmentOverWire(segment);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(BitEqual(segment.core_state, back->core_state));
  segment.core_state = at::randn({48}, at::kDouble);
  EXPECT_THAT(SegmentOverWire(segment).status().message(),
              ::testing::HasSubstr("segment.core_state"));
  EXPECT_GE(MaxSegmentMessageBytes(ContinuousSpec(), 16, 48),
            MaxSegmentMessageBytes(ContinuousSpec(), 16) + 4 * 48);
}

// Masked discrete actions' masks travel as bools; other segments have none,
// and masks of another dtype are refused by name.
TEST(SegmentWireTest, ActionMasksRoundTripAndAreOptional) {
  Segment segment = RealisticSegment();
  absl::StatusOr<Segment> back = SegmentOverWire(segment);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_FALSE(back->action_masks.defined());
  segment.action_masks = at::rand({segment.steps(), 5}) > 0.5;
  back = SegmentOverWire(segment);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_TRUE(at::equal(segment.action_masks, back->action_masks));
  segment.action_masks = at::ones({segment.steps(), 5});
  EXPECT_THAT(SegmentOverWire(segment).status().message(),
              ::testing::HasSubstr("segment.action_masks"));
  EnvSpec masked;
  masked.name = "Masked";
  masked.observation_size = 4;
  masked.discrete = true;
  masked.action_size = 5;
  EnvSpec unmasked = masked;
  masked.action_masks = true;
  EXPECT_GE(MaxSegmentMessageBytes(masked, 16),
            MaxSegmentMessageBytes(unmasked, 16) + 5 * 16);
}

TEST(SegmentWireTest, EmptyFinalObservationsKeepTheirShape) {
  Segment segment = RealisticSegment();
  segment.truncated.zero_();
  segment.final_observations = at::zeros({0, 17});
  // Only the termination at step 11 ends an episode now.
  segment.episode_returns = {1234.5678};
  segment.episode_lengths = {12};
  absl::StatusOr<Segment> back = SegmentOverWire(segment);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->final_observations.sizes(), at::IntArrayRef({0, 17}));
  ExpectSameSegment(segment, *back);
  EXPECT_TRUE(ValidateSegment(*back, ContinuousSpec(), 2048).ok());
}

TEST(SegmentWireTest, NonContiguousFieldsRoundTrip) {
  Segment segment = RealisticSegment();
  segment.observations = at::randn({17, 17}).t();
  segment.actions = at::randn({16, 12}).slice(1, 0, 12, 2);
  segment.rewards = at::randn({32}).slice(0, 0, 32, 2);
  absl::StatusOr<Segment> back = SegmentOverWire(segment);
  ASSERT_TRUE(back.ok()) << back.status();
  ExpectSameSegment(segment, *back);
}

// Byte observations travel as one byte per value and validate against a
// byte spec exactly as they were sent.
TEST(SegmentWireTest, ByteObservationsRoundTripAsBytes) {
  EnvSpec spec;
  spec.name = "Grid";
  spec.observation_size = 2 * 3 * 3;
  spec.observation_shape = {2, 3, 3};
  spec.observation_high = 255;
  spec.discrete = true;
  spec.action_size = 4;
  Segment s = RealisticSegment();
  s.observations = at::randint(0, 256, {17, 18}, at::kByte);
  s.final_observations = at::randint(0, 256, {1, 18}, at::kByte);
  s.actions = at::randint(0, 4, {16, 1}).to(at::kFloat);
  s.episode_lengths = {100, 7};
  pb::Segment proto;
  SegmentToProto(s, &proto);
  EXPECT_EQ(proto.observations().data().size(), 17 * 18);
  EXPECT_LE(static_cast<int64_t>(proto.ByteSizeLong()),
            MaxSegmentMessageBytes(spec, 16));
  absl::StatusOr<Segment> back = SegmentOverWire(s);
  ASSERT_TRUE(back.ok()) << back.status();
  ExpectSameSegment(s, *back);
  EXPECT_EQ(back->observations.scalar_type(), at::kByte);
  EXPECT_TRUE(ValidateSegment(*back, spec, 16).ok())
      << ValidateSegment(*back, spec, 16);
  // The float segment of the same values is not what a byte spec takes.
  Segment floats = *back;
  floats.observations = floats.observations.to(at::kFloat);
  EXPECT_EQ(ValidateSegment(floats, spec, 16).message(),
            "segment field observations has dtype Float, expected Byte");
}

TEST(SegmentWireTest, RefusesWrongDtypeForEachField) {
  struct Case {
    std::function<void(Segment&)> corrupt;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](Segment& s) { s.observations = s.observations.to(at::kDouble); },
       "segment.observations: dtype float64, expected float32 or uint8"},
      {[](Segment& s) { s.actions = s.actions.to(at::kLong); },
       "segment.actions: dtype int64, expected float32"},
      {[](Segment& s) { s.rewards = s.rewards.to(at::kDouble); },
       "segment.rewards: dtype float64, expected float32"},
      {[](Segment& s) { s.terminated = s.terminated.to(at::kByte); },
       "segment.terminated: dtype uint8, expected bool"},
      {[](Segment& s) { s.truncated = s.truncated.to(at::kFloat); },
       "segment.truncated: dtype float32, expected bool"},
      {[](Segment& s) {
         s.final_observations = s.final_observations.to(at::kDouble);
       },
       "segment.final_observations: dtype float64, expected float32 or "
       "uint8"},
      {[](Segment& s) {
         s.behaviour_log_probs = s.behaviour_log_probs.to(at::kBool);
       },
       "segment.behaviour_log_probs: dtype bool, expected float32"},
  };
  for (const Case& c : cases) {
    Segment segment = RealisticSegment();
    c.corrupt(segment);
    absl::StatusOr<Segment> back = SegmentOverWire(segment);
    EXPECT_FALSE(back.ok());
    EXPECT_EQ(back.status().message(), c.message);
  }
}

TEST(SegmentWireTest, NamesTheFieldOfEveryRefusal) {
  pb::Segment proto;
  SegmentToProto(RealisticSegment(), &proto);

  pb::Segment missing = proto;
  missing.clear_final_observations();
  EXPECT_EQ(SegmentFromProto(missing, kNoLimit).status().message(),
            "segment.final_observations: missing");

  pb::Segment short_rewards = proto;
  short_rewards.mutable_rewards()->mutable_data()->resize(15 * 4 - 1);
  EXPECT_EQ(SegmentFromProto(short_rewards, kNoLimit).status().message(),
            "segment.rewards: 59 bytes for shape [16] float32, expected 64");

  pb::Segment unknown = proto;
  unknown.mutable_actions()->set_dtype(static_cast<pb::Tensor::DType>(9));
  EXPECT_EQ(SegmentFromProto(unknown, kNoLimit).status().message(),
            "segment.actions: unknown dtype 9");

  pb::Segment negative = proto;
  negative.mutable_truncated()->set_shape(0, -16);
  EXPECT_THAT(SegmentFromProto(negative, kNoLimit).status().message(),
              HasSubstr("segment.truncated: dimension 0 of shape [-16]"));

  // The observations are the largest tensor: 17 x 17 float32.
  EXPECT_EQ(SegmentFromProto(proto, 17 * 17 * 4 - 1).status().message(),
            "segment.observations: 1156 bytes exceed the limit of 1155");
  EXPECT_TRUE(SegmentFromProto(proto, 17 * 17 * 4).ok());
}

// The wire must neither hide a defect from ValidateSegment nor invent one:
// every segment either fails to decode with a reason or decodes into one
// that validates exactly as the original (with the same message).
TEST(SegmentWireTest, DecodedSegmentValidatesExactlyAsTheOriginal) {
  EnvSpec spec;
  spec.name = "test";
  spec.observation_size = 3;
  spec.action_size = 2;
  spec.action_low.assign(2, -1.0);
  spec.action_high.assign(2, 1.0);
  EnvSpec discrete = spec;
  discrete.discrete = true;
  discrete.action_size = 4;
  discrete.action_low.clear();
  discrete.action_high.clear();

  const auto valid = [] {
    Segment s;
    s.observations = at::randn({5, 3});
    s.actions = at::rand({4, 2});
    s.rewards = at::randn({4});
    s.terminated = at::zeros({4}, at::kBool);
    s.truncated = at::zeros({4}, at::kBool);
    s.truncated[2] = true;
    s.final_observations = at::randn({1, 3});
    s.behaviour_log_probs = at::randn({4});
    s.episode_returns = {2.0};
    s.episode_lengths = {3};
    return s;
  };
  struct Case {
    const char* name;
    const EnvSpec* spec;
    std::function<void(Segment&)> change;
  };
  const std::vector<Case> cases = {
      {"valid", &spec, [](Segment&) {}},
      {"no truncation", &spec,
       [](Segment& s) {
         s.truncated.zero_();
         s.final_observations = at::zeros({0, 3});
         s.episode_returns.clear();
         s.episode_lengths.clear();
       }},
      {"reward beyond the limit", &spec,
       [](Segment& s) { s.rewards[3] = 3e38f; }},
      {"log-prob beyond the limit", &spec,
       [](Segment& s) { s.behaviour_log_probs[0] = -3e38f; }},
      {"an episode too many", &spec,
       [](Segment& s) {
         s.episode_returns.push_back(1.0);
         s.episode_lengths.push_back(1);
       }},
      {"nan episode return", &spec,
       [](Segment& s) { s.episode_returns[0] = NAN; }},
      {"non-contiguous actions", &spec,
       [](Segment& s) {
         s.actions = at::rand({2, 4}).t();
       }},
      {"discrete", &discrete,
       [](Segment& s) {
         s.actions = at::tensor({0.0f, 3.0f, 1.0f, 2.0f}).unsqueeze(1);
       }},
      {"discrete out of range", &discrete,
       [](Segment& s) {
         s.actions = at::tensor({0.0f, 4.0f, 1.0f, 2.0f}).unsqueeze(1);
       }},
      {"observations short", &spec,
       [](Segment& s) {
         s.observations = at::randn({4, 3});
       }},
      {"observations wide", &spec,
       [](Segment& s) {
         s.observations = at::randn({5, 4});
       }},
      {"actions 1-d", &spec, [](Segment& s) { s.actions = at::rand({8}); }},
      {"nan reward", &spec, [](Segment& s) { s.rewards[1] = NAN; }},
      {"infinite observation", &spec,
       [](Segment& s) { s.observations[4][2] = INFINITY; }},
      {"nan log-prob", &spec,
       [](Segment& s) { s.behaviour_log_probs[0] = NAN; }},
      {"double actions", &spec,
       [](Segment& s) { s.actions = s.actions.to(at::kDouble); }},
      {"float terminated", &spec,
       [](Segment& s) { s.terminated = s.terminated.to(at::kFloat); }},
      {"missing final observations", &spec,
       [](Segment& s) { s.final_observations = at::Tensor(); }},
      {"missing rewards", &spec, [](Segment& s) { s.rewards = at::Tensor(); }},
      {"final observation missing for a truncation", &spec,
       [](Segment& s) {
         s.final_observations = at::zeros({0, 3});
       }},
      {"extra final observation", &spec,
       [](Segment& s) {
         s.final_observations = at::zeros({2, 3});
       }},
      {"terminated and truncated", &spec,
       [](Segment& s) { s.terminated[2] = true; }},
      {"episode lists differ", &spec,
       [](Segment& s) { s.episode_lengths.push_back(1); }},
      {"no steps", &spec,
       [](Segment& s) {
         s.observations = at::zeros({1, 3});
         s.actions = at::zeros({0, 2});
         s.rewards = at::zeros({0});
         s.terminated = at::zeros({0}, at::kBool);
         s.truncated = at::zeros({0}, at::kBool);
         s.final_observations = at::zeros({0, 3});
         s.behaviour_log_probs = at::zeros({0});
       }},
  };
  int valid_cases = 0;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    Segment original = valid();
    c.change(original);
    const absl::Status expected = ValidateSegment(original, *c.spec, 4);
    absl::StatusOr<Segment> decoded = SegmentOverWire(original);
    if (decoded.ok()) {
      const absl::Status got = ValidateSegment(*decoded, *c.spec, 4);
      EXPECT_EQ(got.ok(), expected.ok()) << got << " vs " << expected;
      EXPECT_EQ(got.message(), expected.message());
    } else {
      EXPECT_FALSE(expected.ok()) << decoded.status();
      EXPECT_THAT(decoded.status().message(), HasSubstr("segment."));
    }
    valid_cases += expected.ok();
  }
  EXPECT_EQ(valid_cases, 4);
  // Too many steps for this learner: decoding does not know the limit.
  absl::StatusOr<Segment> decoded = SegmentOverWire(valid());
  ASSERT_TRUE(decoded.ok());
  EXPECT_FALSE(ValidateSegment(*decoded, spec, 3).ok());
}

TEST(WeightsWireTest, PolicyWeightsRoundTripAndImport) {
  at::manual_seed(3);
  const EnvSpec spec = ContinuousSpec();
  PolicyNetwork policy(spec, NetworkConfig{});
  RunningMeanStd normalizer(spec.observation_size);
  ASSERT_TRUE(normalizer.Update(at::randn({64, 17}) * 3 + 1).ok());
  const PolicyWeights weights = ExportPolicyWeights(*policy, normalizer, 42);

  pb::Weights proto;
  WeightsToProto(weights, &proto);
  pb::Weights received;
  ASSERT_TRUE(received.ParseFromString(proto.SerializeAsString()));
  absl::StatusOr<PolicyWeights> back = WeightsFromProto(received, kNoLimit);
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->version, 42);
  ASSERT_EQ(back->parameters.size(), weights.parameters.size());
  for (size_t i = 0; i < weights.parameters.size(); ++i) {
    EXPECT_TRUE(BitEqual(weights.parameters[i], back->parameters[i])) << i;
  }
  EXPECT_EQ(std::memcmp(&back->normalizer_count, &weights.normalizer_count,
                        sizeof(double)),
            0);
  EXPECT_TRUE(BitEqual(weights.normalizer_mean, back->normalizer_mean));
  EXPECT_TRUE(BitEqual(weights.normalizer_var, back->normalizer_var));
  EXPECT_EQ(back->normalizer_mean.scalar_type(), at::kDouble);

  at::manual_seed(4);
  PolicyNetwork actor_policy(spec, NetworkConfig{});
  RunningMeanStd actor_normalizer(spec.observation_size);
  ASSERT_TRUE(ImportPolicyWeights(*back, *actor_policy, actor_normalizer).ok());
  const std::vector<at::Tensor> imported = actor_policy->parameters();
  for (size_t i = 0; i < imported.size(); ++i) {
    EXPECT_TRUE(BitEqual(weights.parameters[i], imported[i].detach())) << i;
  }
  EXPECT_TRUE(BitEqual(normalizer.mean(), actor_normalizer.mean()));
}

TEST(WeightsWireTest, NamesTheFieldOfEveryRefusal) {
  PolicyWeights weights;
  weights.version = 1;
  weights.parameters = {at::randn({4, 3}), at::randn({4})};
  weights.normalizer_count = 10.0;
  weights.normalizer_mean = at::zeros({3}, at::kDouble);
  weights.normalizer_var = at::ones({3}, at::kDouble);
  pb::Weights proto;
  WeightsToProto(weights, &proto);
  ASSERT_TRUE(WeightsFromProto(proto, kNoLimit).ok());

  pb::Weights wrong_dtype = proto;
  TensorToProto(at::zeros({4}, at::kLong), wrong_dtype.mutable_parameters(1));
  EXPECT_EQ(WeightsFromProto(wrong_dtype, kNoLimit).status().message(),
            "weights.parameters[1]: dtype int64, expected float32 or float64");

  pb::Weights short_data = proto;
  short_data.mutable_parameters(0)->mutable_data()->pop_back();
  EXPECT_EQ(WeightsFromProto(short_data, kNoLimit).status().message(),
            "weights.parameters[0]: 47 bytes for shape [4, 3] float32, "
            "expected 48");

  pb::Weights no_mean = proto;
  no_mean.clear_normalizer_mean();
  EXPECT_EQ(WeightsFromProto(no_mean, kNoLimit).status().message(),
            "weights.normalizer_mean: missing");

  pb::Weights bool_var = proto;
  TensorToProto(at::ones({3}, at::kBool), bool_var.mutable_normalizer_var());
  EXPECT_EQ(WeightsFromProto(bool_var, kNoLimit).status().message(),
            "weights.normalizer_var: dtype bool, expected float32 or float64");

  EXPECT_EQ(WeightsFromProto(proto, 47).status().message(),
            "weights.parameters[0]: 48 bytes exceed the limit of 47");
}

absl::StatusOr<EnvSpec> SpecOverWire(const EnvSpec& spec) {
  pb::EnvSpec proto;
  EnvSpecToProto(spec, &proto);
  pb::EnvSpec received;
  EXPECT_TRUE(received.ParseFromString(proto.SerializeAsString()));
  return EnvSpecFromProto(received);
}

TEST(EnvSpecWireTest, RoundTrips) {
  EnvSpec continuous = ContinuousSpec();
  continuous.action_low = {-1.0, -0.5, -std::numeric_limits<double>::infinity(),
                           0.1,  -2.0, 0.0};
  continuous.action_high = {1.0, 0.5, std::numeric_limits<double>::infinity(),
                            0.2, 2.0, 1e-9};
  EnvSpec discrete;
  discrete.name = "CartPole";
  discrete.observation_size = 4;
  discrete.discrete = true;
  discrete.action_size = 2;
  discrete.max_episode_steps = 0;
  EnvSpec pixels = discrete;
  pixels.name = "Pixels";
  pixels.observation_size = 3 * 42 * 40;
  pixels.observation_shape = {3, 42, 40};
  pixels.observation_high = 255;
  EnvSpec masked = discrete;
  masked.name = "Masked";
  masked.action_masks = true;
  EnvSpec multi = masked;
  multi.name = "Multi";
  multi.action_size = 7;
  multi.action_nvec = {3, 4};
  EnvSpec dict = discrete;
  dict.name = "Dict";
  dict.observation_size = 22;
  dict.observation_keys = {{"camera", 18, {2, 3, 3}, 255},
                           {"joints", 4, {}, 0}};
  for (const EnvSpec& spec :
       {continuous, discrete, pixels, masked, multi, dict}) {
    absl::StatusOr<EnvSpec> back = SpecOverWire(spec);
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_TRUE(CheckSameSpec(spec, *back).ok()) << CheckSameSpec(spec, *back);
    EXPECT_EQ(back->name, spec.name);
    EXPECT_EQ(back->action_low, spec.action_low);
    EXPECT_EQ(back->action_high, spec.action_high);
    EXPECT_EQ(back->control_dt, spec.control_dt);
    EXPECT_EQ(back->observation_shape, spec.observation_shape);
    EXPECT_EQ(back->observation_high, spec.observation_high);
    EXPECT_EQ(back->action_masks, spec.action_masks);
    EXPECT_EQ(back->action_nvec, spec.action_nvec);
    ASSERT_EQ(back->observation_keys.size(), spec.observation_keys.size());
    for (size_t i = 0; i < spec.observation_keys.size(); ++i) {
      EXPECT_EQ(back->observation_keys[i].name, spec.observation_keys[i].name);
      EXPECT_EQ(back->observation_keys[i].shape,
                spec.observation_keys[i].shape);
    }
  }
}

TEST(EnvSpecWireTest, RefusesImpossibleSpecs) {
  struct Case {
    std::function<void(EnvSpec&)> change;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](EnvSpec& s) { s.name.clear(); }, "spec.name: empty"},
      {[](EnvSpec& s) { s.observation_size = 0; },
       "spec.observation_size: 0, expected >= 1"},
      {[](EnvSpec& s) { s.action_size = -2; },
       "spec.action_size: -2, expected >= 1"},
      {[](EnvSpec& s) { s.action_low.pop_back(); },
       "spec.action_low: 5 values, expected 6 for continuous:6"},
      {[](EnvSpec& s) { s.action_high.push_back(1.0); },
       "spec.action_high: 7 values, expected 6 for continuous:6"},
      {[](EnvSpec& s) { s.action_masks = true; },
       "spec.action_masks: true for continuous actions, which take no masks"},
      {[](EnvSpec& s) {
         s.discrete = true;
         s.action_low.clear();
         s.action_high.clear();
         s.action_nvec = {2, 5};
       },
       "spec.action_nvec: 2x5 sums to at least 7, expected action_size 6"},
      {[](EnvSpec& s) { s.action_nvec = {6}; },
       "spec.action_nvec: 6 for continuous actions, which have none"},
      {[](EnvSpec& s) {
         s.observation_keys = {{"joints", 16, {}, 0}};
       },
       "spec.observation_keys: sizes sum to 16, expected observation_size "
       "17"},
      {[](EnvSpec& s) {
         s.discrete = true;
         s.action_high.clear();
       },
       "spec.action_low: 6 values, expected 0 for discrete:6"},
      {[](EnvSpec& s) {
         s.discrete = true;
         s.action_low.clear();
       },
       "spec.action_high: 6 values, expected 0 for discrete:6"},
      {[](EnvSpec& s) { s.action_low[3] = 1.5; },
       "spec.action_low[3]: 1.5 with action_high[3] 1, expected low < high"},
      {[](EnvSpec& s) { s.action_low[2] = s.action_high[2]; },
       "spec.action_low[2]: 1 with action_high[2] 1, expected low < high"},
      {[](EnvSpec& s) { s.action_high[0] = NAN; },
       "spec.action_low[0]: -1 with action_high[0] nan, expected low < "
       "high"},
      {[](EnvSpec& s) { s.name = std::string(4097, 'x'); },
       "spec.name: 4097 bytes, expected at most 4096"},
      {[](EnvSpec& s) { s.observation_size = 1000000000; },
       "spec.observation_size: 1000000000, expected <= 65536"},
      {[](EnvSpec& s) {
         s.discrete = true;
         s.action_size = 1000000000;
         s.action_low.clear();
         s.action_high.clear();
       },
       "spec.action_size: 1000000000, expected <= 4096"},
      {[](EnvSpec& s) { s.max_episode_steps = int64_t{1} << 40; },
       "spec.max_episode_steps: 1099511627776, expected <= 100000000"},
      {[](EnvSpec& s) { s.max_episode_steps = -1; },
       "spec.max_episode_steps: -1, expected >= 0"},
      {[](EnvSpec& s) { s.control_dt = -0.01; },
       "spec.control_dt: -0.01, expected >= 0"},
      {[](EnvSpec& s) { s.control_dt = INFINITY; },
       "spec.control_dt: inf, expected >= 0"},
      {[](EnvSpec& s) { s.observation_shape = {17}; },
       "spec.observation_shape: 17, expected [channels, height, width] or "
       "nothing"},
      {[](EnvSpec& s) {
         s.observation_shape = {1, 4, 4};
       },
       "spec.observation_shape: 1x4x4 holds 16 values, expected "
       "observation_size 17"},
      {[](EnvSpec& s) {
         s.observation_shape = {17, 17, 17};
       },
       "spec.observation_shape: 17x17x17 holds more than 289 values, "
       "expected observation_size 17"},
      {[](EnvSpec& s) {
         s.observation_shape = {17, -1, -1};
       },
       "spec.observation_shape: 17x-1x-1, expected dimensions in [1, "
       "observation_size 17]"},
      {[](EnvSpec& s) {
         s.observation_shape = {1, 2, 3, 4};
       },
       "spec.observation_shape: 4 dimensions, expected none or 3"},
      {[](EnvSpec& s) { s.observation_high = 256; },
       "spec.observation_high: 256, expected 0 (real values) or 1..255 "
       "(bytes)"},
  };
  for (const Case& c : cases) {
    EnvSpec spec = ContinuousSpec();
    c.change(spec);
    absl::StatusOr<EnvSpec> back = SpecOverWire(spec);
    EXPECT_FALSE(back.ok());
    EXPECT_EQ(back.status().message(), c.message);
  }
}

TEST(EnvSpecWireTest, CheckSameSpecNamesTheFirstDifference) {
  struct Case {
    std::function<void(EnvSpec&)> change;
    std::string message;
  };
  const std::vector<Case> cases = {
      {[](EnvSpec& s) { s.name = "Hopper"; },
       "env spec differs in name: expected \"HalfCheetah\", got \"Hopper\""},
      {[](EnvSpec& s) { s.observation_size = 11; },
       "env spec differs in observation_size: expected 17, got 11"},
      {[](EnvSpec& s) {
         s.discrete = true;
         s.action_low.clear();
         s.action_high.clear();
       },
       "env spec differs in discrete: expected false, got true"},
      {[](EnvSpec& s) {
         s.action_size = 3;
         s.action_low.resize(3);
       },
       "env spec differs in action_size: expected 6, got 3"},
      {[](EnvSpec& s) { s.action_low.pop_back(); },
       "env spec differs in action_low: expected 6 values, got 5"},
      {[](EnvSpec& s) { s.action_low[2] = -1.0000000000000002; },
       "env spec differs in action_low[2]: expected -1, got "
       "-1.0000000000000002"},
      {[](EnvSpec& s) { s.action_high[5] = 0.4; },
       "env spec differs in action_high[5]: expected 1, got 0.4"},
      {[](EnvSpec& s) { s.max_episode_steps = 0; },
       "env spec differs in max_episode_steps: expected 1000, got 0"},
      {[](EnvSpec& s) { s.control_dt = 0.01; },
       "env spec differs in control_dt: expected 0.05, got 0.01"},
      {[](EnvSpec& s) {
         s.observation_shape = {17, 1, 1};
       },
       "env spec differs in observation_shape: expected none, got 17x1x1"},
      {[](EnvSpec& s) { s.observation_high = 1; },
       "env spec differs in observation_high: expected 0, got 1"},
      {[](EnvSpec& s) { s.action_masks = true; },
       "env spec differs in action_masks: expected false, got true"},
      {[](EnvSpec& s) {
         s.action_nvec = {2, 4};
       },
       "env spec differs in action_nvec: expected none, got 2x4"},
      {[](EnvSpec& s) {
         s.observation_keys = {{"joints", 17, {}, 0}};
       },
       "env spec differs in observation_keys: expected 0 entries, got 1"},
      // Several differences: the first in declaration order is named.
      {[](EnvSpec& s) {
         s.control_dt = 0.01;
         s.observation_size = 11;
       },
       "env spec differs in observation_size: expected 17, got 11"},
  };
  const EnvSpec expected = ContinuousSpec();
  EXPECT_TRUE(CheckSameSpec(expected, ContinuousSpec()).ok());
  for (const Case& c : cases) {
    EnvSpec got = ContinuousSpec();
    c.change(got);
    const absl::Status status = CheckSameSpec(expected, got);
    EXPECT_TRUE(absl::IsInvalidArgument(status)) << status;
    EXPECT_EQ(status.message(), c.message);
  }
}

}  // namespace
}  // namespace vantage
