// The JSON request of `vantage advantages --input=FILE`: ParseAdvantageRequest,
// then, for a request that parses, what the command does with it
// (ComputeAdvantages with the request's seed and AdvantagesToJson). The
// estimates cost O(T x |E|); inputs beyond kMaxWork are parsed only.

#include <ATen/ATen.h>

#include <cstddef>
#include <cstdint>
#include <random>
#include <string>

#include "absl/status/statusor.h"
#include "common/advantage/advantage.h"
#include "deploy/cli/advantage_request.h"
#include "tests/fuzz/fuzz_fixtures.h"

namespace {

constexpr int64_t kMaxWork = 1 << 16;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  at::set_num_threads(1);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vantage;
  const std::string json(reinterpret_cast<const char*>(data), size);
  absl::StatusOr<AdvantageRequest> request = ParseAdvantageRequest(json);
  if (!request.ok()) return 0;
  const int64_t steps = request->inputs.rewards.size(0);
  const int64_t members = static_cast<int64_t>(request->config.ensemble.size());
  if (steps * members > kMaxWork) return 0;
  std::mt19937_64 rng(request->seed);
  absl::StatusOr<Advantages> advantages =
      ComputeAdvantages(request->inputs, request->config, rng);
  if (!advantages.ok()) {
    FuzzFail("a parsed request's advantages fail", advantages.status());
  }
  (void)AdvantagesToJson(*advantages);
  return 0;
}
