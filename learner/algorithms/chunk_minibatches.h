#ifndef VANTAGE_LEARNER_ALGORITHMS_CHUNK_MINIBATCHES_H_
#define VANTAGE_LEARNER_ALGORITHMS_CHUNK_MINIBATCHES_H_

// How a recurrent policy trains on a batch: truncated backpropagation
// through time over chunks of UpdateBatch::seq_len steps of one stream,
// each from the state the learner's critic pass found there (zeroed where
// an episode starts inside), minibatches of whole chunks.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <random>
#include <vector>

#include "learner/algorithms/update_batch.h"

namespace vantage {

class PolicyNetworkImpl;
class ValueNetworkImpl;

struct ChunkMinibatch {
  // The batch's rows of the chunks, time-major: step i of chunk j at
  // i * chunks + j.
  at::Tensor rows;
  at::Tensor chunks;  // rows of UpdateBatch::chunk_states
};

// The chunks `ids` (chunk c of stream n is c * N + n) as one minibatch.
ChunkMinibatch MinibatchOfChunks(const UpdateBatch& batch,
                                 const std::vector<int64_t>& ids);

// An epoch's `count` minibatches of whole chunks, shuffled chunk-wise by
// `rng` (each of max(1, chunks / count) chunks; the rest sit the epoch
// out, as rows do for a feed-forward policy).
std::vector<ChunkMinibatch> ShuffledChunkMinibatches(const UpdateBatch& batch,
                                                     int64_t count,
                                                     std::mt19937_64& rng);

// The chunks that start in steps [begin, begin + steps) of every stream
// (begin and steps multiples of seq_len), in order.
ChunkMinibatch ChunksOfSteps(const UpdateBatch& batch, int64_t begin,
                             int64_t steps);

// The policy's outputs and the critic's values on a minibatch's rows (in
// its row order), through the shared trunk with autograd.
struct ChunkOutputs {
  at::Tensor policy;
  at::Tensor values;
};
ChunkOutputs RunChunks(PolicyNetworkImpl& policy, ValueNetworkImpl& value,
                       const UpdateBatch& batch,
                       const ChunkMinibatch& minibatch);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_CHUNK_MINIBATCHES_H_
