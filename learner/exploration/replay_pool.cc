#include "learner/exploration/replay_pool.h"

#include <ATen/ATen.h>
#include <torch/serialize/archive.h>

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "common/env/environment.h"
#include "common/nn/networks.h"
#include "learner/checkpoint/archive_io.h"

namespace vantage {

ReplayPool::ReplayPool(int64_t capacity, int64_t width, int64_t byte_high)
    : capacity_(capacity),
      width_(width),
      byte_high_(byte_high),
      rows_(at::zeros({0, width}, byte_high > 0 ? at::kByte : at::kFloat)) {}

void ReplayPool::Reserve(int64_t rows) {
  if (rows <= rows_.size(0)) return;
  // Grown as it fills (doubling), so that a large capacity costs memory
  // only once the states are there.
  const int64_t grown = std::min(capacity_, std::max(rows, 2 * rows_.size(0)));
  rows_ = at::cat(
      {rows_, at::zeros({grown - rows_.size(0), width_}, rows_.options())});
}

void ReplayPool::Add(const at::Tensor& rows) {
  TORCH_CHECK(rows.scalar_type() == dtype(), "ReplayPool::Add: rows of ",
              rows.scalar_type(), " into a pool of ", dtype());
  const int64_t m = rows.size(0);
  total_added_ += m;
  const at::Tensor kept = m > capacity_ ? rows.slice(0, m - capacity_) : rows;
  Reserve(std::min(capacity_, size_ + kept.size(0)));
  int64_t done = 0;
  while (done < kept.size(0)) {
    const int64_t n = std::min(kept.size(0) - done, capacity_ - next_);
    rows_.slice(0, next_, next_ + n).copy_(kept.slice(0, done, done + n));
    done += n;
    next_ = (next_ + n) % capacity_;
    size_ = std::min(capacity_, size_ + n);
  }
}

at::Tensor ReplayPool::Sample(int64_t n, const at::Generator& generator) const {
  const at::Tensor index =
      at::randint(size_, {n}, generator, at::TensorOptions(at::kLong));
  return rows_.index_select(0, index);
}

void ReplayPool::Save(torch::serialize::OutputArchive& archive,
                      const std::string& prefix) const {
  // A slice would write its whole storage: the rows allocated ahead too.
  archive.write(prefix + ".rows", size_ == rows_.size(0)
                                      ? rows_
                                      : rows_.slice(0, 0, size_).clone());
  archive.write(
      prefix + ".counts",
      at::tensor({capacity_, width_, next_, size_, total_added_}, at::kLong));
}

absl::Status ReplayPool::Load(torch::serialize::InputArchive& archive,
                              const std::string& prefix) {
  at::Tensor rows, counts;
  for (absl::Status status :
       {ReadTensor(archive, prefix + ".rows", rows),
        ReadTensor(archive, prefix + ".counts", counts)}) {
    if (!status.ok()) return status;
  }
  if (counts.scalar_type() != at::kLong || counts.dim() != 1 ||
      counts.numel() != 5) {
    return absl::InvalidArgumentError(
        "replay pool entry 'counts' is malformed");
  }
  const int64_t capacity = counts[0].item<int64_t>();
  const int64_t width = counts[1].item<int64_t>();
  const int64_t next = counts[2].item<int64_t>();
  const int64_t size = counts[3].item<int64_t>();
  const int64_t total = counts[4].item<int64_t>();
  if (capacity != capacity_ || width != width_) {
    return absl::InvalidArgumentError(
        absl::StrCat("replay pool holds ", capacity, " rows of ", width,
                     " values; this run's holds ", capacity_, " of ", width_));
  }
  // A count near the int64 limit would overflow as states are added.
  if (size < 0 || size > capacity || next < 0 || next >= capacity ||
      (size < capacity && next != size) || total < size ||
      total > (int64_t{1} << 62)) {
    return absl::InvalidArgumentError(
        "replay pool entry 'counts' is inconsistent");
  }
  if (rows.dim() != 2 || rows.size(0) != size || rows.size(1) != width ||
      (rows.scalar_type() != at::kFloat && rows.scalar_type() != dtype())) {
    return absl::InvalidArgumentError(
        absl::StrCat("replay pool entry 'rows' is not [", size, ", ", width,
                     "] ", dtype() == at::kByte ? "uint8" : "float32"));
  }
  absl::StatusOr<at::Tensor> stored = StoredRows(rows);
  if (!stored.ok()) return stored.status();
  rows_ = stored->clone();
  next_ = next;
  size_ = size;
  total_added_ = total;
  return absl::OkStatus();
}

absl::StatusOr<at::Tensor> ReplayPool::StoredRows(
    const at::Tensor& rows) const {
  if (rows.scalar_type() == at::kByte) {
    if (rows.gt(byte_high_).any().item<bool>()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "replay pool entry 'rows' holds values above ", byte_high_));
    }
    return rows;
  }
  if (!at::isfinite(rows).all().item<bool>()) {
    return absl::InvalidArgumentError(
        "replay pool entry 'rows' holds non-finite values");
  }
  if (dtype() == at::kFloat) return rows;
  const at::Tensor stored = rows.mul(static_cast<double>(byte_high_))
                                .round_()
                                .clamp_(0, byte_high_)
                                .to(at::kByte);
  // The networks' own scaling must give the rows back (it reads only the
  // spec's highest value).
  EnvSpec bytes;
  bytes.observation_high = byte_high_;
  if (!at::equal(NetworkInputs(bytes, stored), rows)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "replay pool entry 'rows' is float32 but not observations of 0..",
        byte_high_, " scaled by 1/", byte_high_,
        ", which this run's pool keeps as bytes"));
  }
  return stored;
}

}  // namespace vantage
