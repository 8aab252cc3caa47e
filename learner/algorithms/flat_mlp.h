#ifndef VANTAGE_LEARNER_ALGORITHMS_FLAT_MLP_H_
#define VANTAGE_LEARNER_ALGORITHMS_FLAT_MLP_H_

// A tanh MLP trained without autograd: its Linear layers' parameters lie in
// one flat float array (a module's parameters laid end to end), its forward
// pass is one BLAS call per layer keeping each layer's output, and its
// backward pass is written out by hand into the matching flat gradient
// array. The first-order updates (FlatActorCritic) and EX2's model
// (FlatExemplarModel) are built from these.

#include <ATen/core/Tensor.h>

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"

namespace torch::nn {
class ModuleList;
}  // namespace torch::nn

namespace vantage {

// Where each of a list of parameter tensors begins in one flat array (the
// list's order, end to end), and which of them a layout has claimed.
class FlatParameterClaims {
 public:
  // Unimplemented unless every tensor is contiguous float on the CPU.
  static absl::StatusOr<FlatParameterClaims> Create(
      std::vector<at::Tensor> tensors);

  int64_t size() const { return size_; }
  const std::vector<at::Tensor>& tensors() const { return tensors_; }
  const std::vector<int64_t>& offsets() const { return offsets_; }

  // `tensor`'s offset if it is one of the tensors (the same tensor, not an
  // equal one) and not claimed yet; -1 otherwise (a tensor shared by two
  // layers is claimed once).
  int64_t Claim(const at::Tensor& tensor);
  bool AllClaimed() const;

 private:
  std::vector<at::Tensor> tensors_;
  std::vector<int64_t> offsets_;
  std::vector<bool> claimed_;
  int64_t size_ = 0;
};

class FlatMlp {
 public:
  FlatMlp() = default;  // no layers
  // The biased torch::nn::Linear layers of `layers` on `inputs` values,
  // ending in `outputs`; tanh after each but the last, and after the last
  // too when `squash_last` (a trunk whose outputs feed other layers).
  static absl::StatusOr<FlatMlp> LayOut(const torch::nn::ModuleList& layers,
                                        int64_t inputs, int64_t outputs,
                                        bool squash_last,
                                        FlatParameterClaims& claims);

  bool empty() const { return layers_.empty(); }
  int64_t outputs() const { return empty() ? 0 : layers_.back().outputs; }

  // [rows, outputs()] of the last Forward: the last layer's outputs (after
  // tanh if squash_last). Writable: Backward never reads them (a caller
  // takes a squashed output's tanh derivative from them before).
  float* output() { return outputs_.back().data(); }

  // `inputs` [rows, inputs] must stay unchanged until Backward.
  void Forward(const float* parameters, const float* inputs, int64_t rows);

  // From `gradient` [rows, outputs()] = d loss / d (the last layer's
  // output before any tanh; used as scratch): every layer's weight and bias
  // gradients written (not added) into `gradients` at their offsets, and d
  // loss / d inputs into `d_inputs` [rows, inputs] unless null.
  void Backward(const float* parameters, float* gradients, const float* inputs,
                int64_t rows, std::vector<float>& gradient,
                float* d_inputs = nullptr);

 private:
  struct Layer {
    int64_t inputs = 0;
    int64_t outputs = 0;
    int64_t weight = 0;  // offsets: [outputs, inputs] row-major
    int64_t bias = 0;
  };
  std::vector<Layer> layers_;
  bool squash_last_ = false;
  // Each layer's output of the last Forward (after tanh but the last).
  std::vector<std::vector<float>> outputs_;
  std::vector<float> scratch_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_FLAT_MLP_H_
