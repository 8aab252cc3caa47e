#include "learner/parallel/replica_group.h"

namespace vantage {
namespace {

class SoloGroup : public ReplicaGroup {
 public:
  int rank() const override { return 0; }
  int world_size() const override { return 1; }
  void AllReduceSum(std::vector<at::Tensor>&) override {}
  void Broadcast(std::vector<at::Tensor>&, int) override {}
};

}  // namespace

std::shared_ptr<ReplicaGroup> SoloReplicaGroup() {
  return std::make_shared<SoloGroup>();
}

uint64_t ReplicaSeed(uint64_t run_seed, int rank) {
  if (rank == 0) return run_seed;
  // SplitMix64's finaliser over seed and rank: neighbouring seeds and ranks
  // give unrelated streams.
  uint64_t z = run_seed + 0x9e3779b97f4a7c15ULL * static_cast<uint64_t>(rank);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace vantage
