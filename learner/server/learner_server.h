#ifndef VANTAGE_LEARNER_SERVER_LEARNER_SERVER_H_
#define VANTAGE_LEARNER_SERVER_LEARNER_SERVER_H_

#include <atomic>
#include <functional>
#include <string>

#include "absl/status/status.h"
#include "common/env/environment.h"
#include "common/net/security_options.h"
#include "learner/learner_config.h"
#include "learner/parallel/gloo_replica_group.h"
#include "learner/run/evaluate_policy.h"
#include "learner/run/progress_columns.h"
#include "learner/run/recording_config.h"
#include "learner/service/actor_gateway.h"
#include "proto/run_config.pb.h"

namespace vantage {

struct LearnerServerConfig {
  // The run's learner (its batch: rollouts_per_batch env streams of
  // horizon steps, over all replicas; the spec is `spec`) and its
  // recording, as a run's plan gives them (deploy/run/run_plan.h).
  LearnerConfig learner;
  RecordingConfig recording;
  pb::RunConfig run_config;  // resolved; actors receive it
  // The run's environment, from the learner's own configuration: actors
  // must register exactly this spec (a resumed run checks that its
  // checkpoint has it too).
  EnvSpec spec;
  // What clients may make the learner hold (actors, env slots, value
  // magnitudes, idle streams, gRPC threads and memory).
  GatewayLimits limits;
  ServiceLimits service_limits;
  int max_server_threads = 600;
  int64_t max_grpc_memory_bytes = int64_t{1} << 30;
  std::string listen = "127.0.0.1:0";
  std::string port_file;     // written with the bound port once serving
  SecurityOptions security;  // TLS and the token every actor must send
  // Prometheus endpoint HOST:PORT (port 0: a free one); empty: none.
  std::string metrics_address;
  // If set, the metrics port goes there once serving (see port_file.h).
  std::string metrics_port_file;
  // Evaluations every `eval_every` updates (0: none) with `evaluate`, on a
  // low-priority thread of rank 0 (learner/run/background_evaluator.h).
  int64_t eval_every = 0;
  EvaluatePolicy evaluate;
  // This learner's place among the run's data-parallel learners (the
  // run config's distributed.learners); each trains on its own actors'
  // share of the batch. Only rank 0 writes the run directory.
  ReplicaGroupConfig replicas;
};

// `vantage learner`: serves actors over gRPC, trains on their segments and
// publishes every new version until the run's steps are done or `stop` is
// set. A replica of a data-parallel run joins the others before serving;
// if one is lost, the update fails here too (Unavailable) and the run is
// continued by restarting every replica from the last checkpoint.
absl::Status RunLearnerServer(
    const LearnerServerConfig& config, const std::atomic<bool>& stop,
    const std::function<void(const ProgressRow&)>& on_update);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_SERVER_LEARNER_SERVER_H_
