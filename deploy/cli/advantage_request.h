#ifndef VANTAGE_DEPLOY_CLI_ADVANTAGE_REQUEST_H_
#define VANTAGE_DEPLOY_CLI_ADVANTAGE_REQUEST_H_

// The JSON face of the advantage library used by `vantage advantages`: one
// rollout of a single environment stream in, the estimates out.

#include <cstdint>
#include <string>

#include "absl/status/statusor.h"
#include "common/advantage/advantage.h"
#include "common/advantage/advantage_config.h"

namespace vantage {

struct AdvantageRequest {
  AdvantageConfig config;
  uint64_t seed = 0;
  AdvantageInputs inputs;  // double tensors shaped [T, 1]
};

// Parses and checks the request: every key present, every list of length T
// (the length of `rewards`), every number finite, the config valid. The
// error names the offending key.
absl::StatusOr<AdvantageRequest> ParseAdvantageRequest(const std::string& json);

// {"gae", "biased", "mixed", "mask", "returns"} as one JSON object.
std::string AdvantagesToJson(const Advantages& advantages);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_ADVANTAGE_REQUEST_H_
