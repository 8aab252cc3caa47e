#ifndef VANTAGE_DEPLOY_CLI_SECURITY_FLAGS_H_
#define VANTAGE_DEPLOY_CLI_SECURITY_FLAGS_H_

// --auth_token_file and the --tls_* flags of train, learner and actor.

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/net/security_options.h"

namespace vantage {

std::vector<std::string> SecurityFlagNames();

// The files the flags name, checked for the side that uses them (`server`:
// the learner), with the token read from its file.
absl::StatusOr<SecurityOptions> SecurityFromFlags(bool server);

// The token file's path, for commands that pass it on to child processes.
std::string AuthTokenFileFlag();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_SECURITY_FLAGS_H_
