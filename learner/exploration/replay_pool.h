#ifndef VANTAGE_LEARNER_EXPLORATION_REPLAY_POOL_H_
#define VANTAGE_LEARNER_EXPLORATION_REPLAY_POOL_H_

#include <ATen/core/Generator.h>
#include <ATen/core/Tensor.h>

#include <cstdint>
#include <string>

#include "absl/status/status.h"

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
  ReplayPool(int64_t capacity, int64_t width);

  // Rows [M, width] float32; of more than `capacity` rows only the last
  // `capacity` stay.
  void Add(const at::Tensor& rows);
  // [n, width]; the pool must not be empty.
  at::Tensor Sample(int64_t n, const at::Generator& generator) const;

  int64_t size() const { return size_; }  // rows held
  // Rows ever added (what EX2's minimum size counts).
  int64_t total_added() const { return total_added_; }

  // As the entries `prefix`.rows and `prefix`.counts.
  void Save(torch::serialize::OutputArchive& archive,
            const std::string& prefix) const;
  // A pool of another width or capacity, or malformed or non-finite rows,
  // is an InvalidArgument error naming the entry; the pool is unchanged.
  absl::Status Load(torch::serialize::InputArchive& archive,
                    const std::string& prefix);

 private:
  // Room for at least `rows` rows (at most capacity_).
  void Reserve(int64_t rows);

  int64_t capacity_;
  int64_t width_;
  // [allocated, width]: grown as states arrive, up to capacity_ rows; the
  // first size_ rows are filled.
  at::Tensor rows_;
  int64_t next_ = 0;  // where the next row goes
  int64_t size_ = 0;
  int64_t total_added_ = 0;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_EXPLORATION_REPLAY_POOL_H_
