#ifndef VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_
#define VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_

#include <string>

#include "learner/service/actor_gateway.h"
#include "learner/service/security.h"
#include "proto/run_config.pb.h"

namespace vantage {

struct TrainRequest {
  // The fields set by flags given on the command line.
  pb::RunConfig flags;
  std::string config_file;  // --config: JSON RunConfig under the flags
  std::string run_dir;      // --run_dir: where the run is recorded
  std::string resume;       // --resume: a run directory to continue
  // Distributed: the security flags its learner and actors get.
  std::string auth_token_file;
  std::string tls_cert;
  std::string tls_key;
  std::string tls_ca;
};

// `vantage train`: a progress line while a terminal watches, a final
// `RESULT train ... mean_return=<last 100 episodes>` line. Bad flags or
// files: one line on stderr, exit code 2.
int RunTrainCommand(const TrainRequest& request);

struct LearnerRequest {
  TrainRequest train;        // the run's settings, as for train
  std::string listen;        // HOST:PORT; port 0 picks a free one
  std::string port_file;     // the bound port is written here
  std::string metrics;       // Prometheus HOST:PORT; empty: none
  SecurityOptions security;  // TLS and the token actors must send
  GatewayLimits limits;      // what clients may make the learner hold
  ServiceLimits service_limits;
  int max_server_threads = 600;
  int64_t max_grpc_memory_bytes = int64_t{1} << 30;
};

// `vantage learner`: serves actors (see deploy/learner_server.h) until the
// run's steps are done or SIGINT/SIGTERM; a line per update on stderr and
// the RESULT train line at the end.
int RunLearnerCommand(const LearnerRequest& request);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_TRAIN_COMMAND_H_
