#ifndef VANTAGE_DEPLOY_CLI_LEARNER_LIMIT_FLAGS_H_
#define VANTAGE_DEPLOY_CLI_LEARNER_LIMIT_FLAGS_H_

// The learner's limits (what clients can make it hold, docs/security.md):
// flags of `vantage learner`, and of `vantage train`, which passes the
// ones given on to the learners it starts.

#include <string>
#include <vector>

#include "absl/status/status.h"

namespace vantage {

// Declared, not included: the server's config reaches LibTorch, and the
// commands that only check or pass the flags on need not.
struct LearnerServerConfig;

std::vector<std::string> LearnerLimitFlagNames();

// Sets server.limits, server.service_limits' idle stream timeout and the
// gRPC server's bounds from the flags; an out-of-range value is an error
// naming its flag.
absl::Status ReadLearnerLimits(LearnerServerConfig& server);

// The same checks, for a command that only passes the flags on.
absl::Status CheckLearnerLimits();

// "--name=value" of each limit flag given, for a child learner.
std::vector<std::string> GivenLearnerLimitArgs();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_LEARNER_LIMIT_FLAGS_H_
