#ifndef VANTAGE_ACTOR_REMOTE_REMOTE_ACTOR_H_
#define VANTAGE_ACTOR_REMOTE_REMOTE_ACTOR_H_

// `vantage actor`: an actor core streaming to a learner over gRPC.

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "common/net/security_options.h"

namespace vantage {

struct RemoteActorConfig {
  std::string learner = "127.0.0.1:50051";  // HOST:PORT
  std::string env = "InvertedPendulum";
  // A Python environment's factory arguments (JSON); empty: the learner's
  // run config's, once registered (its spec is probed without them).
  std::string env_kwargs;
  int num_envs = 1;
  // The environments' seed. Absent: ActorEnvSeed of the run's seed and the
  // actor id of the registration, so that actors started with the same
  // flags (a Deployment's pods) reset their environments differently.
  std::optional<uint64_t> seed;
  std::string name = "actor";
  // Reconnection attempts after the learner went away or refused; 0: give
  // up at the first failure, -1: forever.
  int max_reconnects = -1;
  absl::Duration initial_backoff = absl::Milliseconds(200);
  absl::Duration max_backoff = absl::Seconds(10);
  int max_message_bytes = 256 << 20;
  SecurityOptions security;  // TLS and the auth token sent on every call
  // Prometheus endpoint HOST:PORT (port 0: a free one); empty: none.
  std::string metrics_address;
  // If set, the metrics port goes there once serving (see port_file.h).
  std::string metrics_port_file;
};

// A seed for the environments of the actor registered as `actor_id` in a
// run seeded `run_seed`: distinct for distinct ids (a bijection of the id
// for a given run seed) and scattered far from the seeds run_seed + i that the
// launcher gives its own actors.
uint64_t ActorEnvSeed(uint64_t run_seed, int64_t actor_id);

// Registers, acts with the newest weights (picked up between segments; in
// a sync run it waits for version v + 1 after each horizon), streams
// segments, and reconnects with exponential backoff when the learner goes
// away, keeping its environments. Returns OK once `stop` is set, or the
// error that ended it (a refusal, or the reconnects exhausted).
absl::Status RunRemoteActor(const RemoteActorConfig& config,
                            const std::atomic<bool>& stop);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_REMOTE_REMOTE_ACTOR_H_
