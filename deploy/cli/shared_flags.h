#ifndef VANTAGE_DEPLOY_CLI_SHARED_FLAGS_H_
#define VANTAGE_DEPLOY_CLI_SHARED_FLAGS_H_

// Flags that several commands read, with one meaning everywhere. A flag
// only one command reads is defined in that command's file.

#include <cstdint>
#include <string>

#include "absl/flags/declare.h"

ABSL_DECLARE_FLAG(std::string, env);
ABSL_DECLARE_FLAG(std::string, env_kwargs);
ABSL_DECLARE_FLAG(int, envs);
ABSL_DECLARE_FLAG(uint64_t, seed);
ABSL_DECLARE_FLAG(std::string, learner);
ABSL_DECLARE_FLAG(std::string, metrics);
ABSL_DECLARE_FLAG(std::string, metrics_port_file);
ABSL_DECLARE_FLAG(std::string, checkpoint);
ABSL_DECLARE_FLAG(std::string, out);

#endif  // VANTAGE_DEPLOY_CLI_SHARED_FLAGS_H_
