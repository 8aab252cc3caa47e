#ifndef VANTAGE_LEARNER_ALGORITHMS_FLAT_OPTIMIZER_H_
#define VANTAGE_LEARNER_ALGORITHMS_FLAT_OPTIMIZER_H_

// A fused optimiser (FlatAdam, FlatRmsprop): one pass over FlatActorCritic's
// flat parameter array, its state kept in the flat layout while training
// and carried into checkpoints through a torch::optim optimiser over the
// same parameter tensors, so that checkpoints keep LibTorch's format.

#include "absl/status/status.h"

namespace torch::optim {
class Optimizer;
}  // namespace torch::optim

namespace vantage {

class FlatOptimizer {
 public:
  virtual ~FlatOptimizer() = default;

  // One step with the settings of `optimizer`'s first parameter group (its
  // learning rate among them) on `parameters` with `gradients`.
  virtual void Step(const torch::optim::Optimizer& optimizer, float* parameters,
                    const float* gradients) = 0;

  // The state into `optimizer`'s per-parameter state (for its save()), and
  // back (after its load()): InvalidArgument when the loaded state does
  // not fit.
  virtual void StoreInto(torch::optim::Optimizer& optimizer) const = 0;
  virtual absl::Status LoadFrom(const torch::optim::Optimizer& optimizer) = 0;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_FLAT_OPTIMIZER_H_
