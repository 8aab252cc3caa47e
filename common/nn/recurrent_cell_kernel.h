#ifndef VANTAGE_COMMON_NN_RECURRENT_CELL_KERNEL_H_
#define VANTAGE_COMMON_NN_RECURRENT_CELL_KERNEL_H_

// One step of a GRU or LSTM cell as acting needs it, without LibTorch's
// per-operator dispatch: the weights of one published version laid out
// once as float arrays, and the gates of all of an actor's environments as
// two BLAS matrix products (inputs and hidden states against the stacked
// gate weights) followed by one pass of the gate functions. LibTorch's
// conventions: gates stacked as (i, f, g, o) for the LSTM and (r, z, n) for
// the GRU, whose candidate is tanh(W_in x + b_in + r * (W_hn h + b_hn)).
// Its states agree with torch::nn::GRUCell's and LSTMCell's up to float
// rounding, step after step (tests/common/nn/recurrent_cell_kernel_test.cc).

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"

namespace at {
class Tensor;
}  // namespace at

namespace vantage {

class RecurrentCellKernel {
 public:
  enum class Kind { kGru, kLstm };

  // A copy of a cell's parameters as they are now: weight_ih [G x H, I],
  // weight_hh [G x H, H], bias_ih and bias_hh [G x H] (G = 3 for a GRU, 4
  // for an LSTM). InvalidArgument when the shapes do not fit.
  static absl::StatusOr<RecurrentCellKernel> Create(Kind kind,
                                                    const at::Tensor& weight_ih,
                                                    const at::Tensor& weight_hh,
                                                    const at::Tensor& bias_ih,
                                                    const at::Tensor& bias_hh);

  Kind kind() const { return kind_; }
  int64_t input_size() const { return inputs_; }
  int64_t hidden_size() const { return hidden_; }

  // Floats per row of a state: the hidden state, then an LSTM's cell
  // state (RecurrentTrunkImpl's layout).
  int64_t state_size() const {
    return kind_ == Kind::kLstm ? 2 * hidden_ : hidden_;
  }

  // One step for `rows` environments: `inputs` [rows, input_size], the
  // states [rows, state_size()] read and overwritten with the next. A row
  // whose episode starts is zeroed by the caller before the step.
  void Step(const float* inputs, int64_t rows, float* states);

 private:
  RecurrentCellKernel() = default;

  Kind kind_ = Kind::kGru;
  int64_t inputs_ = 0;
  int64_t hidden_ = 0;
  int64_t gates_ = 0;  // G x H
  std::vector<float> weight_ih_, weight_hh_, bias_ih_, bias_hh_;
  // Scratch, grown to the largest batch seen: the input and hidden
  // projections, [rows, G x H] each.
  std::vector<float> from_input_, from_hidden_;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_RECURRENT_CELL_KERNEL_H_
