#ifndef VANTAGE_LEARNER_ALGORITHMS_A2C_FLAT_RMSPROP_H_
#define VANTAGE_LEARNER_ALGORITHMS_A2C_FLAT_RMSPROP_H_

// RMSProp in one pass over a flat parameter array, in either arithmetic
// A2C offers: torch::optim::RMSprop's (mean square from 0, eps outside
// the root) or TensorflowRmsprop's (from 1, eps inside). Like FlatAdam it
// keeps its state flat while training and goes into checkpoints through
// the torch optimiser's per-parameter state (RMSpropParamState for both),
// so checkpoints keep their format and either path resumes the other's.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/status/status.h"
#include "learner/algorithms/flat_optimizer.h"

namespace vantage {

enum class RmspropArithmetic { kPytorch, kTensorflow };

class FlatRmsprop : public FlatOptimizer {
 public:
  // For the parameter tensors `parameters` laid out one after another from
  // `offsets` in a flat array of `size` floats.
  FlatRmsprop(std::vector<at::Tensor> parameters, std::vector<int64_t> offsets,
              int64_t size, RmspropArithmetic arithmetic);

  // One step with the learning rate, alpha and eps of `rmsprop`'s first
  // group (a torch::optim::RMSprop or a TensorflowRmsprop).
  void Step(const torch::optim::Optimizer& rmsprop, float* parameters,
            const float* gradients) override;

  // The state into `rmsprop`'s per-parameter state (for its save()), and
  // back (after its load()): InvalidArgument when the loaded state's steps
  // differ between parameters or its mean squares do not fit.
  void StoreInto(torch::optim::Optimizer& rmsprop) const override;
  absl::Status LoadFrom(const torch::optim::Optimizer& rmsprop) override;

 private:
  // The mean square a parameter starts from: 0 or 1 by the arithmetic.
  float initial_square() const;

  std::vector<at::Tensor> parameters_;
  std::vector<int64_t> offsets_;
  RmspropArithmetic arithmetic_;
  int64_t step_ = 0;
  std::vector<float> square_avg_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_A2C_FLAT_RMSPROP_H_
