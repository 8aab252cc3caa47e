#ifndef VANTAGE_COMMON_NN_TANH_MLP_H_
#define VANTAGE_COMMON_NN_TANH_MLP_H_

#include <torch/nn/module.h>
#include <torch/nn/modules/container/modulelist.h>
#include <torch/nn/modules/linear.h>

#include <cstdint>
#include <vector>

namespace vantage {

// Linear layers with tanh between them (none after the last).
class TanhMlpImpl : public torch::nn::Module {
 public:
  TanhMlpImpl(int64_t inputs, const std::vector<int64_t>& hidden,
              int64_t outputs, double output_gain);
  at::Tensor forward(const at::Tensor& x);
  // The Linear layers in order (for code that runs it without modules).
  const torch::nn::ModuleList& layers() const { return layers_; }

 private:
  torch::nn::ModuleList layers_;
};
TORCH_MODULE(TanhMlp);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_TANH_MLP_H_
