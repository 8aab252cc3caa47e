#ifndef VANTAGE_LEARNER_EXPLORATION_REPLAY_POOL_H_
#define VANTAGE_LEARNER_EXPLORATION_REPLAY_POOL_H_

#include <ATen/core/Generator.h>
#include <ATen/core/Tensor.h>

#include <cstdint>
#include <string>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace torch::serialize {
class InputArchive;
class OutputArchive;
}  // namespace torch::serialize

namespace vantage {

// The newest `capacity` rows of width `width` ever added (first in, first
// out), sampled uniformly with replacement: the earlier states an exemplar
// model contrasts new ones with.
class ReplayPool {
 public:
  // Rows of float32, or (`byte_high` > 0) of byte observations as they
  // arrive, uint8 values in [0, byte_high]: a quarter of the memory and of
  // the checkpoint (an image pool of EX2's size is a gigabyte in float32).
  ReplayPool(int64_t capacity, int64_t width, int64_t byte_high = 0);

  // Rows [M, width] of the pool's type; of more than `capacity` rows only
  // the last `capacity` stay.
  void Add(const at::Tensor& rows);
  // [n, width] of the pool's type; the pool must not be empty.
  at::Tensor Sample(int64_t n, const at::Generator& generator) const;
  at::ScalarType dtype() const { return rows_.scalar_type(); }

  int64_t size() const { return size_; }  // rows held
  // Rows ever added (what EX2's minimum size counts).
  int64_t total_added() const { return total_added_; }

  // As the entries `prefix`.rows and `prefix`.counts.
  void Save(torch::serialize::OutputArchive& archive,
            const std::string& prefix) const;
  // A pool of another width or capacity, or malformed or non-finite rows,
  // is an InvalidArgument error naming the entry; the pool is unchanged.
  // A byte pool also takes float32 rows (checkpoints from before byte
  // pools) that are exactly its bytes scaled by 1 / byte_high, as the
  // networks scale them.
  absl::Status Load(torch::serialize::InputArchive& archive,
                    const std::string& prefix);

 private:
  // `rows` of the pool's type: float32 rows converted for a byte pool when
  // they are exactly its scaled bytes.
  absl::StatusOr<at::Tensor> StoredRows(const at::Tensor& rows) const;

  // Room for at least `rows` rows (at most capacity_).
  void Reserve(int64_t rows);

  int64_t capacity_;
  int64_t width_;
  int64_t byte_high_;
  // [allocated, width]: grown as states arrive, up to capacity_ rows; the
  // first size_ rows are filled.
  at::Tensor rows_;
  int64_t next_ = 0;  // where the next row goes
  int64_t size_ = 0;
  int64_t total_added_ = 0;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_EXPLORATION_REPLAY_POOL_H_
