// A recurrent policy's update works on chunks: started from the states the
// critic's pass over the whole rollouts found, the chunks repeat that pass
// exactly, and an epoch's shuffled minibatches hold every row once, each
// chunk whole.

#include "learner/algorithms/chunk_minibatches.h"

#include <ATen/ATen.h>

#include <random>
#include <set>
#include <vector>

#include "common/nn/networks.h"
#include "gtest/gtest.h"
#include "learner/batch/recurrent_critic.h"
#include "learner/batch/training_batch.h"
#include "tests/fakes/vector_spec.h"

namespace vantage {
namespace {

constexpr int64_t kSteps = 12;
constexpr int64_t kStreams = 3;
constexpr int64_t kSeqLen = 4;

Rollout RandomRollout(int64_t state_size, int64_t seed) {
  Rollout r;
  r.observations = at::randn({kSteps + 1, 5});
  r.actions = at::randn({kSteps, 2});
  r.rewards = at::randn({kSteps});
  r.terminated = at::zeros({kSteps}, at::kBool);
  r.truncated = at::zeros({kSteps}, at::kBool);
  r.terminated[(seed * 5 + 2) % kSteps] = true;
  r.truncated[(seed * 7 + 5) % kSteps] = true;
  r.final_observations = at::randn({1, 5});
  r.behaviour_log_probs = at::randn({kSteps});
  r.policy_versions = at::zeros({kSteps}, at::kLong);
  r.core_state = at::randn({state_size}) * 0.5;
  return r;
}

class ChunkMinibatchesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    at::manual_seed(7);
    spec_ = VectorSpec(false, 5, 2);
    NetworkConfig config;
    config.hidden = {8};
    config.core = Core::kGru;
    config.core_size = 6;
    policy_ = PolicyNetwork(spec_, config);
    value_ = MakeValueNetwork(spec_, config, *policy_);
    std::vector<Rollout> rollouts;
    for (int64_t n = 0; n < kStreams; ++n) {
      rollouts.push_back(RandomRollout(config.core_state_size(), n));
    }
    pass_ = RunRecurrentCritic(*value_, rollouts,
                               [](const at::Tensor& raw) { return raw; });
    std::vector<at::Tensor> observations, terminated, truncated;
    for (const Rollout& r : rollouts) {
      observations.push_back(r.observations.slice(0, 0, kSteps));
      terminated.push_back(r.terminated);
      truncated.push_back(r.truncated);
    }
    batch_.horizon = kSteps;
    batch_.streams = kStreams;
    batch_.observations =
        at::stack(observations, 1).reshape({kSteps * kStreams, -1});
    batch_.seq_len = kSeqLen;
    batch_.starts =
        EpisodeStarts(at::stack(terminated, 1), at::stack(truncated, 1))
            .reshape({-1});
    batch_.chunk_states = ChunkStartStates(pass_, kSeqLen);
  }

  EnvSpec spec_;
  PolicyNetwork policy_{nullptr};
  ValueNetwork value_{nullptr};
  RecurrentCriticPass pass_;
  UpdateBatch batch_;
};

TEST_F(ChunkMinibatchesTest, ChunksRepeatTheCriticsPass) {
  at::NoGradGuard no_grad;
  // The critic's values of step t of stream n, time-major like the batch.
  const at::Tensor expected = pass_.values.slice(0, 0, kStreams * (kSteps + 1))
                                  .reshape({kStreams, kSteps + 1})
                                  .slice(1, 0, kSteps)
                                  .t()
                                  .reshape({-1});
  const ChunkMinibatch all = ChunksOfSteps(batch_, 0, kSteps);
  ASSERT_EQ(all.rows.size(0), kSteps * kStreams);
  const ChunkOutputs out = RunChunks(*policy_, *value_, batch_, all);
  EXPECT_TRUE(
      at::allclose(out.values, expected.index_select(0, all.rows), 1e-5, 1e-6))
      << (out.values - expected.index_select(0, all.rows)).abs().max();
  // A chunk alone gives the same: it needs nothing but its start state.
  const ChunkMinibatch one = MinibatchOfChunks(batch_, {2 * kStreams + 1});
  EXPECT_TRUE(at::allclose(RunChunks(*policy_, *value_, batch_, one).values,
                           expected.index_select(0, one.rows), 1e-5, 1e-6));
}

TEST_F(ChunkMinibatchesTest, AnEpochHoldsEveryRowOnceInWholeChunks) {
  std::mt19937_64 rng(3);
  const std::vector<ChunkMinibatch> minibatches =
      ShuffledChunkMinibatches(batch_, 3, rng);
  ASSERT_EQ(minibatches.size(), 3u);  // 9 chunks, 3 each
  std::set<int64_t> rows;
  for (const ChunkMinibatch& m : minibatches) {
    const int64_t chunks = m.chunks.size(0);
    ASSERT_EQ(m.rows.size(0), chunks * kSeqLen);
    for (int64_t j = 0; j < chunks; ++j) {
      const int64_t id = m.chunks[j].item<int64_t>();
      for (int64_t i = 0; i < kSeqLen; ++i) {
        const int64_t row = m.rows[i * chunks + j].item<int64_t>();
        // Step i of chunk id: its stream, kSeqLen steps from its start.
        EXPECT_EQ(row % kStreams, id % kStreams);
        EXPECT_EQ(row / kStreams, (id / kStreams) * kSeqLen + i);
        EXPECT_TRUE(rows.insert(row).second) << "row " << row << " twice";
      }
    }
  }
  EXPECT_EQ(rows.size(), static_cast<size_t>(kSteps * kStreams));
}

}  // namespace
}  // namespace vantage
