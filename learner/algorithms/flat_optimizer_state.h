#ifndef VANTAGE_LEARNER_ALGORITHMS_FLAT_OPTIMIZER_STATE_H_
#define VANTAGE_LEARNER_ALGORITHMS_FLAT_OPTIMIZER_STATE_H_

// The fused optimisers (FlatAdam, FlatRmsprop) keep their state as flat
// float arrays laid out as FlatActorCritic lays out the parameters, and
// write it into checkpoints through a torch::optim optimiser's
// per-parameter state, so that checkpoints keep LibTorch's format. These
// are the pieces of that translation both share.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"

namespace vantage {

// torch::optim's key for a parameter's state.
std::string OptimizerStateKey(const at::Tensor& parameter);

// `parameter`'s values in `flat` (beginning at `offset`) as a new tensor
// of its shape.
at::Tensor FlatStateTensor(const std::vector<float>& flat, int64_t offset,
                           const at::Tensor& parameter);

// `source`'s values into `flat` from `offset`: InvalidArgument naming
// `optimizer` and the parameter's `index` when it is undefined or does not
// hold `numel` values.
absl::Status CopyStateToFlat(const at::Tensor& source, int64_t offset,
                             int64_t numel, std::vector<float>& flat,
                             const char* optimizer, size_t index);

// Every parameter's state must have taken the same number of steps: the
// first one seen sets `step` (-1 until then), the others are compared.
absl::Status CheckSameStep(int64_t parameter_step, const char* optimizer,
                           int64_t& step);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_FLAT_OPTIMIZER_STATE_H_
