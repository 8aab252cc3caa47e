#ifndef VANTAGE_DEPLOY_LEARNER_SERVER_H_
#define VANTAGE_DEPLOY_LEARNER_SERVER_H_

#include <atomic>
#include <functional>
#include <string>

#include "absl/status/status.h"
#include "deploy/local_training.h"
#include "learner/service/security.h"
#include "proto/run_config.pb.h"

namespace vantage {

struct LearnerServerConfig {
  // The learner's settings, the batch (num_envs env streams of horizon
  // steps), the run length and the run directory, as in local mode.
  LocalTrainingConfig training;
  pb::RunConfig run_config;  // resolved; actors receive it
  std::string listen = "127.0.0.1:0";
  std::string port_file;     // written with the bound port once serving
  SecurityOptions security;  // TLS and the token every actor must send
  // Prometheus endpoint HOST:PORT (port 0: a free one); empty: none.
  std::string metrics_address;
};

// `vantage learner`: serves actors over gRPC, trains on their segments and
// publishes every new version until the run's steps are done or `stop` is
// set. The environment spec comes with the first actor's registration.
absl::Status RunLearnerServer(
    const LearnerServerConfig& config, const std::atomic<bool>& stop,
    const std::function<void(const ProgressRow&)>& on_update);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_LEARNER_SERVER_H_
