#ifndef VANTAGE_COMMON_NN_FLOAT_COPY_H_
#define VANTAGE_COMMON_NN_FLOAT_COPY_H_

// A tensor's values as a plain float array, for the kernels that act
// without LibTorch (mlp_policy_kernel, recurrent_cell_kernel).

#include <ATen/ATen.h>

#include <vector>

namespace vantage {

inline std::vector<float> FloatVector(const at::Tensor& tensor) {
  const at::Tensor flat = tensor.detach().to(at::kFloat).contiguous();
  return std::vector<float>(flat.data_ptr<float>(),
                            flat.data_ptr<float>() + flat.numel());
}

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_FLOAT_COPY_H_
