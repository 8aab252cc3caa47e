#ifndef VANTAGE_LEARNER_PARALLEL_REPLICA_GROUP_H_
#define VANTAGE_LEARNER_PARALLEL_REPLICA_GROUP_H_

// The learner replicas of one data-parallel run. Each replica trains on the
// rollouts of its own actors; every gradient and every statistic that must
// describe the global batch is summed across the group, so all replicas
// keep identical weights.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <memory>
#include <vector>

namespace vantage {

// Every replica calls the same collectives in the same order with tensors
// of the same shapes and dtypes (contiguous, CPU). A replica that is gone,
// or silent for longer than the group's timeout, makes a collective throw
// (std::exception); LearnerCore undoes the update in progress and reports
// it as an Unavailable error.
class ReplicaGroup {
 public:
  virtual ~ReplicaGroup() = default;

  virtual int rank() const = 0;
  virtual int world_size() const = 0;

  // Element-wise sums over the replicas, in place, in one collective.
  virtual void AllReduceSum(std::vector<at::Tensor>& tensors) = 0;
  // `root`'s values everywhere, in place.
  virtual void Broadcast(std::vector<at::Tensor>& tensors, int root) = 0;
};

// The group of one learner: collectives leave the tensors as they are.
std::shared_ptr<ReplicaGroup> SoloReplicaGroup();

// The seed of replica `rank`'s generator (minibatch order, the rho mask):
// the run's seed for rank 0, so one replica repeats a single learner, and
// a well-mixed different one for every other rank.
uint64_t ReplicaSeed(uint64_t run_seed, int rank);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_PARALLEL_REPLICA_GROUP_H_
