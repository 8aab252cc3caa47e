#include "learner/parallel/gloo_replica_group.h"

#include <gloo/allreduce_ring.h>
#include <gloo/rendezvous/context.h>
#include <gloo/rendezvous/store.h>

#include <chrono>
#include <exception>
#include <map>
#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#include <torch/csrc/distributed/c10d/TCPStore.hpp>
#include <utility>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "learner/parallel/replica_group.h"

namespace vantage {
namespace {

// Gloo's rendezvous through c10d's store (the TCPStore rank 0 serves), under
// a prefix of its own.
class StoreForGloo : public gloo::rendezvous::Store {
 public:
  StoreForGloo(c10::intrusive_ptr<c10d::Store> store, std::string prefix)
      : store_(std::move(store)), prefix_(std::move(prefix)) {}

  void set(const std::string& key, const std::vector<char>& data) override {
    store_->set(prefix_ + key, std::vector<uint8_t>(data.begin(), data.end()));
  }
  std::vector<char> get(const std::string& key) override {
    const std::vector<uint8_t> value = store_->get(prefix_ + key);
    return std::vector<char>(value.begin(), value.end());
  }
  void wait(const std::vector<std::string>& keys) override {
    store_->wait(Prefixed(keys));
  }
  void wait(const std::vector<std::string>& keys,
            const std::chrono::milliseconds& timeout) override {
    store_->wait(Prefixed(keys), timeout);
  }

 private:
  std::vector<std::string> Prefixed(const std::vector<std::string>& keys) {
    std::vector<std::string> prefixed;
    for (const std::string& key : keys) prefixed.push_back(prefix_ + key);
    return prefixed;
  }

  c10::intrusive_ptr<c10d::Store> store_;
  const std::string prefix_;
};

// Sums run as Gloo's ring all-reduce on a context of their own, called on
// this thread: ProcessGroupGloo hands every collective to a worker thread
// and waits for it, which on a 2-core VM made a gradient's all-reduce
// 3-20 times slower (docs/benchmarks.md), and an update makes one per
// minibatch. Broadcasts, rare, go through ProcessGroupGloo.
class GlooGroup : public ReplicaGroup {
 public:
  GlooGroup(c10::intrusive_ptr<c10d::Store> store,
            c10::intrusive_ptr<c10d::ProcessGroupGloo> group,
            std::shared_ptr<gloo::rendezvous::Context> sums, int rank,
            int world_size)
      : store_(std::move(store)),
        group_(std::move(group)),
        sums_(std::move(sums)),
        rank_(rank),
        world_size_(world_size) {}

  int rank() const override { return rank_; }
  int world_size() const override { return world_size_; }

  void AllReduceSum(std::vector<at::Tensor>& tensors) override {
    if (tensors.empty()) return;
    const at::Tensor flat = Flatten(tensors);
    Ring& ring = RingFor(flat.scalar_type(), flat.numel());
    ring.staging.copy_(flat);
    ring.algorithm->run();
    Unflatten(ring.staging, tensors);
  }

  void Broadcast(std::vector<at::Tensor>& tensors, int root) override {
    if (tensors.empty()) return;
    std::vector<at::Tensor> flat = {Flatten(tensors)};
    c10d::BroadcastOptions options;
    options.rootRank = root;
    group_->broadcast(flat, options)->wait();
    Unflatten(flat[0], tensors);
  }

 private:
  // All tensors must share a dtype; a single one passes through.
  static at::Tensor Flatten(const std::vector<at::Tensor>& tensors) {
    if (tensors.size() == 1) return tensors[0].contiguous();
    std::vector<at::Tensor> pieces;
    for (const at::Tensor& t : tensors) pieces.push_back(t.reshape({-1}));
    return at::cat(pieces);
  }
  static void Unflatten(const at::Tensor& flat,
                        std::vector<at::Tensor>& tensors) {
    if (tensors.size() == 1) {
      if (!flat.is_same(tensors[0])) tensors[0].copy_(flat);
      return;
    }
    int64_t offset = 0;
    for (at::Tensor& t : tensors) {
      const int64_t n = t.numel();
      t.copy_(flat.slice(0, offset, offset + n).view_as(t));
      offset += n;
    }
  }

  // A ring all-reduce bound to a staging buffer of one dtype and size.
  // Every replica makes its rings in the same order (the same calls), as
  // Gloo's slot numbering needs.
  struct Ring {
    at::Tensor staging;
    std::unique_ptr<gloo::Algorithm> algorithm;
  };

  Ring& RingFor(at::ScalarType dtype, int64_t numel) {
    auto [entry, inserted] = rings_.try_emplace({dtype, numel});
    Ring& ring = entry->second;
    if (!inserted) return ring;
    ring.staging = at::zeros({numel}, at::TensorOptions().dtype(dtype));
    if (dtype == at::kFloat) {
      ring.algorithm = std::make_unique<gloo::AllreduceRing<float>>(
          sums_, std::vector<float*>{ring.staging.data_ptr<float>()},
          static_cast<int>(numel));
    } else if (dtype == at::kDouble) {
      ring.algorithm = std::make_unique<gloo::AllreduceRing<double>>(
          sums_, std::vector<double*>{ring.staging.data_ptr<double>()},
          static_cast<int>(numel));
    } else {
      rings_.erase(entry);
      throw std::invalid_argument("replica sums take float or double tensors");
    }
    return ring;
  }

  c10::intrusive_ptr<c10d::Store> store_;
  c10::intrusive_ptr<c10d::ProcessGroupGloo> group_;
  std::shared_ptr<gloo::rendezvous::Context> sums_;
  std::map<std::pair<at::ScalarType, int64_t>, Ring> rings_;
  const int rank_;
  const int world_size_;
};

// HOST:PORT into its parts.
absl::Status SplitAddress(const std::string& address, std::string& host,
                          int& port) {
  const size_t colon = address.rfind(':');
  if (colon == std::string::npos || colon == 0 ||
      !absl::SimpleAtoi(address.substr(colon + 1), &port) || port < 1 ||
      port > 65535) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the rendezvous must be HOST:PORT with a port in [1, 65535], got '",
        address, "'"));
  }
  host = address.substr(0, colon);
  return absl::OkStatus();
}

}  // namespace

absl::Status ReplicaGroupConfig::Validate() const {
  if (world_size < 1 || world_size > 64) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the number of learner replicas must be in [1, 64], got ", world_size));
  }
  if (rank < 0 || rank >= world_size) {
    return absl::InvalidArgumentError(absl::StrCat(
        "the learner rank must be in [0, ", world_size - 1, "], got ", rank));
  }
  if (!(timeout > absl::ZeroDuration())) {
    return absl::InvalidArgumentError("the replica timeout must be > 0");
  }
  if (world_size == 1) return absl::OkStatus();
  std::string host;
  int port = 0;
  return SplitAddress(rendezvous, host, port);
}

absl::StatusOr<std::shared_ptr<ReplicaGroup>> JoinReplicaGroup(
    const ReplicaGroupConfig& config) {
  if (absl::Status status = config.Validate(); !status.ok()) return status;
  if (config.world_size == 1) return SoloReplicaGroup();
  std::string host;
  int port = 0;
  if (absl::Status status = SplitAddress(config.rendezvous, host, port);
      !status.ok()) {
    return status;
  }
  const auto timeout =
      std::chrono::milliseconds(absl::ToInt64Milliseconds(config.timeout));
  try {
    c10d::TCPStoreOptions options;
    options.port = static_cast<uint16_t>(port);
    options.isServer = config.rank == 0;
    options.numWorkers = config.world_size;
    options.waitWorkers = false;
    options.timeout = timeout;
    auto store = c10::make_intrusive<c10d::TCPStore>(host, options);
    auto gloo_options = c10d::ProcessGroupGloo::Options::create(timeout);
    // Loopback rendezvous: every replica is on this machine; otherwise each
    // replica's own hostname must resolve to an address the others reach.
    std::shared_ptr<gloo::transport::Device> device =
        host == "127.0.0.1" || host == "localhost"
            ? c10d::ProcessGroupGloo::createDeviceForHostname("127.0.0.1")
            : c10d::ProcessGroupGloo::createDefaultDevice();
    gloo_options->devices.push_back(device);
    gloo_options->threads = 1;
    auto group = c10::make_intrusive<c10d::ProcessGroupGloo>(
        store, config.rank, config.world_size, gloo_options);
    auto sums = std::make_shared<gloo::rendezvous::Context>(config.rank,
                                                            config.world_size);
    sums->setTimeout(timeout);
    StoreForGloo sums_store(store, "vantage/sums/");
    sums->connectFullMesh(sums_store, device);
    return std::shared_ptr<ReplicaGroup>(std::make_shared<GlooGroup>(
        store, group, std::move(sums), config.rank, config.world_size));
  } catch (const std::exception& error) {
    return absl::UnavailableError(
        absl::StrCat("learner replica ", config.rank, " of ", config.world_size,
                     " could not join the group at ", config.rendezvous, ": ",
                     error.what()));
  }
}

}  // namespace vantage
