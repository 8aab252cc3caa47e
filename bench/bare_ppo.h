#ifndef VANTAGE_BENCH_BARE_PPO_H_
#define VANTAGE_BENCH_BARE_PPO_H_

// The baseline of the learner and train benchmarks: the least a PPO update
// must do, written directly against LibTorch.

#include <torch/nn/modules/container/sequential.h>
#include <torch/optim/adam.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "learner/algorithms/policy_updater.h"

namespace vantage {

struct BarePpoShape {
  int64_t observations = 17;
  int64_t actions = 6;
  std::vector<int64_t> hidden = {64, 64};  // tanh layers
  int minibatches = 32;
  int epochs = 10;
};

// Shuffled minibatches, both networks forward, the Gaussian
// log-probability, the clipped surrogate and the value loss, backward, one
// Adam step: nothing of the learner's bookkeeping.
class BarePpo {
 public:
  explicit BarePpo(const BarePpoShape& shape);

  void Update(const UpdateBatch& batch);

 private:
  BarePpoShape shape_;
  torch::nn::Sequential policy_;
  torch::nn::Sequential value_;
  at::Tensor log_std_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

// The spec of a task of `shape`'s sizes (HalfCheetah's by default), its
// actions bounded by +-1.
EnvSpec BenchSpec(const BarePpoShape& shape);

// A batch of `samples` random rows of `shape`'s sizes.
UpdateBatch SyntheticBatch(const BarePpoShape& shape, int64_t samples);

}  // namespace vantage

#endif  // VANTAGE_BENCH_BARE_PPO_H_
