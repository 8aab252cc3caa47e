#ifndef VANTAGE_DEPLOY_RUN_LAUNCHER_H_
#define VANTAGE_DEPLOY_RUN_LAUNCHER_H_

// The main job on one machine: learner processes and N actor processes of
// this same binary over loopback gRPC, supervised.

#include <atomic>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "proto/run_config.pb.h"

namespace vantage {

struct LaunchConfig {
  pb::RunConfig run_config;  // resolved, mode "distributed"
  std::string run_dir;       // may be empty
  // Where the learner's port file and the config it reads go.
  std::string work_dir;
  // Continue the run in run_dir from its last checkpoint.
  bool resume = false;
  // Restarts of crashed actors before the run is given up (a long run on
  // preemptible nodes loses actors many times).
  int max_actor_restarts = 100;
  // Restarts of a crashed learner (each resumes from the run's last
  // checkpoint; needs a run_dir with one) before the run is given up.
  int max_learner_restarts = 5;
  // Passed to the learner and every actor as --auth_token_file, --tls_cert,
  // --tls_key, --tls_ca when set (the same files serve both ends).
  std::string auth_token_file;
  std::string tls_cert;
  std::string tls_key;
  std::string tls_ca;
  // If set ("HOST:PORT" or "PORT"), every process serves Prometheus
  // metrics on HOST: learner rank r on PORT + r, actor i on PORT + K + i
  // (PORT 0: each a free one), and the run's scrape targets are kept in
  // <run_dir or work_dir>/prometheus_targets.json (scrape_targets.h),
  // rewritten when a restarted process serves elsewhere and emptied when
  // the run ends or is stopped (a failed run keeps them, so that
  // Prometheus sees it down).
  std::string metrics_address;
  // More flags for every learner (`vantage train`'s learner limits).
  std::vector<std::string> learner_args;
};

// Starts `vantage learner` on 127.0.0.1 with a free port (with
// distributed.learners = K > 1, K data-parallel learners, rank 0 serving
// their rendezvous on another free port), then the actors (actor i gets
// seed + i, so one actor repeats a local run, and serves learner i mod K),
// restarts an actor that dies with seeds of its own (ActorLifeSeed, logged),
// restarts a learner that dies from
// the run's last checkpoint on the same port (with K > 1 every learner, as
// replicas only train together; the actors reconnect keeping their
// environments), forwards `stop` (SIGINT/SIGTERM) to every process, and
// returns when the learners finish the run (the actors are then stopped).
// The learners' output (rank 0's progress, the RESULT line) passes
// through.
absl::Status RunDistributedTraining(const LaunchConfig& config,
                                    const std::atomic<bool>& stop);

// The environments' seed of actor `actor` in its `life`-th life (0: the
// first start) in a run seeded `run_seed`: run_seed + actor first, then a
// seed of the actor's and the life's, so that an actor restarted after a
// crash that its episodes cause does not replay them and crash again.
uint64_t ActorLifeSeed(uint64_t run_seed, int actor, int life);

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_RUN_LAUNCHER_H_
