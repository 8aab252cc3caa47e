#ifndef VANTAGE_LEARNER_PARALLEL_GLOO_REPLICA_GROUP_H_
#define VANTAGE_LEARNER_PARALLEL_GLOO_REPLICA_GROUP_H_

// Learner replicas in separate processes (on one machine or several),
// joined by LibTorch's c10d: a TCPStore served by rank 0 for the
// rendezvous and ProcessGroupGloo for the collectives.

#include <memory>
#include <string>

#include "absl/status/statusor.h"
#include "absl/time/time.h"

namespace vantage {

class ReplicaGroup;

struct ReplicaGroupConfig {
  int rank = 0;
  int world_size = 1;
  // HOST:PORT of the rendezvous store, which rank 0 serves (so HOST must
  // be one of rank 0's addresses); every rank names the same one.
  std::string rendezvous;
  // How long joining, and each collective, may wait for the other
  // replicas before failing.
  absl::Duration timeout = absl::Seconds(300);

  absl::Status Validate() const;
};

// Joins the group; returns once every replica has joined (or fails after
// `timeout`, naming the rendezvous). A group of one needs no rendezvous and
// is SoloReplicaGroup().
absl::StatusOr<std::shared_ptr<ReplicaGroup>> JoinReplicaGroup(
    const ReplicaGroupConfig& config);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_PARALLEL_GLOO_REPLICA_GROUP_H_
