#include "learner/algorithms/flat_optimizer_state.h"

#include <ATen/ATen.h>

#include <cstring>

#include "absl/strings/str_cat.h"

namespace vantage {

std::string OptimizerStateKey(const at::Tensor& parameter) {
  return c10::guts::to_string(parameter.unsafeGetTensorImpl());
}

at::Tensor FlatStateTensor(const std::vector<float>& flat, int64_t offset,
                           const at::Tensor& parameter) {
  at::Tensor tensor = at::empty_like(parameter.detach());
  std::memcpy(tensor.data_ptr<float>(), flat.data() + offset,
              sizeof(float) * parameter.numel());
  return tensor;
}

absl::Status CopyStateToFlat(const at::Tensor& source, int64_t offset,
                             int64_t numel, std::vector<float>& flat,
                             const char* optimizer, size_t index) {
  if (!source.defined() || source.numel() != numel) {
    return absl::InvalidArgumentError(
        absl::StrCat("the ", optimizer, " state of parameter ", index,
                     " does not fit its ", numel, " values"));
  }
  const at::Tensor values = source.to(at::kFloat).contiguous();
  std::memcpy(flat.data() + offset, values.data_ptr<float>(),
              sizeof(float) * numel);
  return absl::OkStatus();
}

absl::Status CheckSameStep(int64_t parameter_step, const char* optimizer,
                           int64_t& step) {
  if (step >= 0 && parameter_step != step) {
    return absl::InvalidArgumentError(
        absl::StrCat("the ", optimizer,
                     " state's parameters took different numbers of steps (",
                     step, " and ", parameter_step, ")"));
  }
  step = parameter_step;
  return absl::OkStatus();
}

}  // namespace vantage
