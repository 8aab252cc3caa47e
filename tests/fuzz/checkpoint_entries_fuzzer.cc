// What a checkpoint's pickles decide, without LibTorch's unpickler in the
// way (see checkpoint_fuzzer.cc): a real learner's checkpoint (PPO with an
// EX2 bonus, FuzzEx2LearnerConfig, after two updates, so that the EX2
// model has fitted and its pool holds states) with some of its top-level
// tensor entries (EX2's among them) replaced by tensors the input
// describes, written by LibTorch's own archive writer and read back by
// ReadFuzzEx2Checkpoint; a learner that loads must pass CheckLoadedLearner.
//
// The input is a list of edits, each
//   key (1 byte: an index into the entries, modulo their count),
//   dtype (1 byte: 0 keeps the entry's, else one of kDTypes),
//   rank (1 byte: 0 keeps the entry's shape, else rank - 1 dimensions),
//   a size per dimension (1 byte each, 0..16),
//   the elements' bytes (zero past the end of the input).
// The entries of the optimiser and reward scaler archives are not edited.

#include <ATen/ATen.h>
#include <torch/serialize/archive.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "common/rollout/segment_queue.h"
#include "learner/learner_core.h"
#include "tests/fuzz/fuzz_fixtures.h"

namespace vantage {
namespace {

constexpr int kMaxEdits = 8;
constexpr at::ScalarType kDTypes[] = {at::kFloat, at::kDouble, at::kLong,
                                      at::kInt,   at::kByte,   at::kBool,
                                      at::kHalf};

class Bytes {
 public:
  Bytes(const uint8_t* data, size_t size) : data_(data), size_(size) {}
  bool empty() const { return at_ >= size_; }
  uint8_t Next() { return at_ < size_ ? data_[at_++] : 0; }
  void Fill(uint8_t* out, size_t n) {
    if (n == 0) return;
    const size_t take = std::min(n, size_ - std::min(at_, size_));
    if (take > 0) std::memcpy(out, data_ + at_, take);
    std::memset(out + take, 0, n - take);
    at_ += take;
  }

 private:
  const uint8_t* data_;
  size_t size_;
  size_t at_ = 0;
};

struct Reference {
  std::unique_ptr<LearnerCore> learner;
  std::vector<std::string> keys;  // top-level tensor entries
  std::vector<at::Tensor> tensors;
};

const Reference& GetReference() {
  static const Reference* reference = [] {
    auto* made = new Reference;
    const LearnerConfig config = FuzzEx2LearnerConfig();
    absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
        LearnerCore::Create(config);
    if (!learner.ok()) FuzzFail("no reference learner", learner.status());
    made->learner = *std::move(learner);
    // Two updates, the second continuing the first's streams.
    for (int64_t round = 0; round < 2; ++round) {
      SegmentQueue queue(config.rollouts_per_batch);
      for (int64_t slot = 0; slot < config.rollouts_per_batch; ++slot) {
        Segment segment =
            FuzzSegment(config.spec, config.horizon, slot,
                        made->learner->policy_version(), 10 * round + slot);
        segment.sequence = round;
        (void)queue.Send(std::move(segment));
      }
      queue.Close();
      absl::StatusOr<UpdateStats> stats = made->learner->RunUpdate(queue);
      if (!stats.ok()) FuzzFail("the reference cannot update", stats.status());
    }
    torch::serialize::OutputArchive written;
    made->learner->Save(written);
    std::ostringstream bytes;
    written.save_to(bytes);
    torch::serialize::InputArchive read;
    std::istringstream in(bytes.str());
    read.load_from(in);
    for (const std::string& key : read.keys()) {
      at::Tensor tensor;
      if (read.try_read(key, tensor)) {
        made->keys.push_back(key);
        made->tensors.push_back(tensor);
      }
    }
    return made;
  }();
  return *reference;
}

at::Tensor EditedTensor(const at::Tensor& original, Bytes& in) {
  const uint8_t dtype = in.Next();
  const uint8_t rank = in.Next();
  const at::ScalarType type =
      dtype == 0
          ? original.scalar_type()
          : kDTypes[(dtype - 1) % (sizeof(kDTypes) / sizeof(kDTypes[0]))];
  std::vector<int64_t> shape = original.sizes().vec();
  if (rank != 0) {
    shape.assign((rank - 1) % 4, 0);
    for (int64_t& size : shape) size = in.Next() % 17;
  }
  at::Tensor tensor = at::empty(shape, at::TensorOptions().dtype(type));
  in.Fill(static_cast<uint8_t*>(tensor.data_ptr()), tensor.nbytes());
  // Any byte but 0 or 1 in a bool tensor is undefined behaviour in LibTorch,
  // and LibTorch's own reader would never produce one.
  if (type == at::kBool) {
    uint8_t* flags = static_cast<uint8_t*>(tensor.data_ptr());
    for (size_t i = 0; i < tensor.nbytes(); ++i) flags[i] &= 1;
  }
  return tensor;
}

}  // namespace
}  // namespace vantage

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  at::set_num_threads(1);
  vantage::GetReference();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vantage;
  const Reference& reference = GetReference();
  torch::serialize::OutputArchive archive;
  reference.learner->Save(archive);
  Bytes in(data, size);
  for (int edit = 0; edit < kMaxEdits && !in.empty(); ++edit) {
    const size_t key = in.Next() % reference.keys.size();
    archive.write(reference.keys[key],
                  EditedTensor(reference.tensors[key], in));
  }
  static const std::string path = FuzzTempPath("checkpoint_entries.pt");
  {
    std::ostringstream bytes;
    archive.save_to(bytes);
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    file << bytes.str();
    if (!file) return 0;
  }
  absl::StatusOr<std::unique_ptr<LearnerCore>> learner =
      ReadFuzzEx2Checkpoint(path);
  if (learner.ok()) CheckLoadedLearner(**learner);
  std::remove(path.c_str());
  return 0;
}
