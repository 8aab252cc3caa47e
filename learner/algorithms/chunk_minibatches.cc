#include "learner/algorithms/chunk_minibatches.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <numeric>

#include "common/nn/networks.h"

namespace vantage {

ChunkMinibatch MinibatchOfChunks(const UpdateBatch& batch,
                                 const std::vector<int64_t>& ids) {
  const int64_t n = batch.streams;
  const int64_t length = batch.seq_len;
  std::vector<int64_t> rows;
  rows.reserve(ids.size() * length);
  for (int64_t i = 0; i < length; ++i) {
    for (int64_t id : ids) {
      const int64_t chunk = id / n;
      const int64_t stream = id % n;
      rows.push_back((chunk * length + i) * n + stream);
    }
  }
  return ChunkMinibatch{at::tensor(rows, at::kLong),
                        at::tensor(ids, at::kLong)};
}

std::vector<ChunkMinibatch> ShuffledChunkMinibatches(const UpdateBatch& batch,
                                                     int64_t count,
                                                     std::mt19937_64& rng) {
  const int64_t chunks = batch.horizon / batch.seq_len * batch.streams;
  std::vector<int64_t> order(chunks);
  std::iota(order.begin(), order.end(), 0);
  std::shuffle(order.begin(), order.end(), rng);
  const int64_t size =
      std::max<int64_t>(1, chunks / std::max<int64_t>(1, count));
  std::vector<ChunkMinibatch> minibatches;
  for (int64_t begin = 0; begin + size <= chunks; begin += size) {
    minibatches.push_back(MinibatchOfChunks(
        batch, std::vector<int64_t>(order.begin() + begin,
                                    order.begin() + begin + size)));
  }
  return minibatches;
}

ChunkMinibatch ChunksOfSteps(const UpdateBatch& batch, int64_t begin,
                             int64_t steps) {
  std::vector<int64_t> ids;
  for (int64_t c = begin / batch.seq_len; c < (begin + steps) / batch.seq_len;
       ++c) {
    for (int64_t n = 0; n < batch.streams; ++n) {
      ids.push_back(c * batch.streams + n);
    }
  }
  return MinibatchOfChunks(batch, ids);
}

ChunkOutputs RunChunks(PolicyNetworkImpl& policy, ValueNetworkImpl& value,
                       const UpdateBatch& batch,
                       const ChunkMinibatch& minibatch) {
  const int64_t chunks = minibatch.chunks.size(0);
  RecurrentTrunk trunk = policy.trunk();  // shares the module
  const at::Tensor features =
      trunk->Unroll(batch.observations.index_select(0, minibatch.rows),
                    batch.starts.index_select(0, minibatch.rows)
                        .reshape({batch.seq_len, chunks}),
                    batch.chunk_states.index_select(0, minibatch.chunks));
  return ChunkOutputs{policy.Head(features), value.Head(features)};
}

}  // namespace vantage
