// Actor registration: bytes -> pb::RegisterRequest -> EnvSpecFromProto and
// CheckSameSpec against the run's pinned spec, then the whole of
// ActorGateway::Register (published weights, timeout zero) on a fresh
// gateway per input. A spec that decodes must survive a round trip, and a
// granted registration's session must attach.

#include <ATen/ATen.h>

#include <cstddef>
#include <cstdint>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "common/nn/policy_weights.h"
#include "common/rollout/segment_queue.h"
#include "learner/service/actor_gateway.h"
#include "proto/vantage.pb.h"
#include "proto/wire_format.h"
#include "tests/fuzz/fuzz_fixtures.h"

namespace vantage {
namespace {

void CheckSpec(const pb::EnvSpec& proto) {
  absl::StatusOr<EnvSpec> spec = EnvSpecFromProto(proto);
  if (!spec.ok()) return;
  pb::EnvSpec encoded;
  EnvSpecToProto(*spec, &encoded);
  absl::StatusOr<EnvSpec> again = EnvSpecFromProto(encoded);
  if (!again.ok()) FuzzFail("a valid spec's copy is invalid", again.status());
  if (absl::Status same = CheckSameSpec(*spec, *again); !same.ok()) {
    FuzzFail("a valid spec changed in a round trip", same);
  }
  (void)CheckSameSpec(FuzzContinuousSpec(), *spec);
}

PolicyWeights SomeWeights() {
  PolicyWeights weights;
  weights.version = 0;
  weights.parameters = {at::zeros({2, 4}), at::zeros({2})};
  weights.normalizer_count = 1.0;
  weights.normalizer_mean = at::zeros({4}, at::kDouble);
  weights.normalizer_var = at::ones({4}, at::kDouble);
  return weights;
}

void CheckRegister(const pb::RegisterRequest& request) {
  GatewayConfig config;
  config.spec = FuzzContinuousSpec();
  config.max_segment_steps = kFuzzMaxSteps;
  // Small enough that the slot limit is reachable from one request.
  config.limits.max_envs_per_actor = 64;
  config.limits.max_live_env_slots = 100;
  SegmentQueue queue(4);
  ActorGateway gateway(config, queue);
  static const PolicyWeights weights = SomeWeights();
  gateway.Publish(weights);
  for (int i = 0; i < 2; ++i) {
    absl::StatusOr<pb::RegisterResponse> response =
        gateway.Register(request, "fuzz", absl::ZeroDuration());
    if (!response.ok()) return;
    absl::StatusOr<int64_t> attached = gateway.Attach(response->session());
    if (!attached.ok() || *attached != response->actor_id()) {
      FuzzFail("a granted session does not attach", attached.status());
    }
    gateway.Detach(*attached);
  }
  gateway.Close();
}

}  // namespace
}  // namespace vantage

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  at::set_num_threads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vantage;
  pb::RegisterRequest request;
  if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
  CheckSpec(request.spec());
  CheckRegister(request);
  return 0;
}
