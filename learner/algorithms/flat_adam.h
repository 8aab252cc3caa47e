#ifndef VANTAGE_LEARNER_ALGORITHMS_FLAT_ADAM_H_
#define VANTAGE_LEARNER_ALGORITHMS_FLAT_ADAM_H_

// Adam as torch::optim::Adam computes it (no weight decay, no AMSGrad), in
// one pass over a flat parameter array instead of a dozen operators per
// parameter tensor. Its state is kept in the flat layout while training
// and goes into checkpoints through a torch::optim::Adam over the same
// parameter tensors, so that checkpoints keep their format and either
// optimiser resumes from the other's.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "learner/algorithms/flat_optimizer.h"

namespace vantage {

class FlatAdam : public FlatOptimizer {
 public:
  // For the parameter tensors `parameters` laid out one after another from
  // `offsets` in a flat array of `size` floats.
  FlatAdam(std::vector<at::Tensor> parameters, std::vector<int64_t> offsets,
           int64_t size);

  // With a torch::optim::Adam: one step of `adam`'s settings (its first group's
  // learning rate, betas and eps) on `parameters` with `gradients`.
  void Step(const torch::optim::Optimizer& adam, float* parameters,
            const float* gradients) override;

  // The state into `adam`'s per-parameter state (for its save()), and back
  // (after its load()): InvalidArgument when the loaded state's steps
  // differ between parameters or its moments do not fit.
  void StoreInto(torch::optim::Optimizer& adam) const override;
  absl::Status LoadFrom(const torch::optim::Optimizer& adam) override;

 private:
  std::vector<at::Tensor> parameters_;
  std::vector<int64_t> offsets_;
  int64_t step_ = 0;
  std::vector<float> exp_avg_;
  std::vector<float> exp_avg_sq_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_FLAT_ADAM_H_
