// The recurrent cell kernel against LibTorch's own cells: random weights,
// several batch sizes, states carried over 50 steps with episode starts
// zeroing rows on the way.

#include "common/nn/recurrent_cell_kernel.h"

#include <ATen/ATen.h>
#include <torch/nn/modules/rnn.h>

#include <cstring>
#include <tuple>
#include <type_traits>
#include <vector>

#include "gtest/gtest.h"

namespace vantage {
namespace {

constexpr int64_t kInputs = 11;
constexpr int64_t kHidden = 24;
constexpr int kSteps = 50;

std::vector<float> Floats(const at::Tensor& t) {
  const at::Tensor c = t.detach().contiguous();
  return std::vector<float>(c.data_ptr<float>(),
                            c.data_ptr<float>() + c.numel());
}

// Step by step: the kernel's state and the cell's stay within `tolerance`
// of each other (absolute; states are in (-1, 1), an LSTM's cell a few).
template <typename Cell>
void ExpectAgreement(RecurrentCellKernel::Kind kind, Cell& cell, int64_t rows) {
  absl::StatusOr<RecurrentCellKernel> kernel = RecurrentCellKernel::Create(
      kind, cell->weight_ih, cell->weight_hh, cell->bias_ih, cell->bias_hh);
  ASSERT_TRUE(kernel.ok()) << kernel.status();
  const bool lstm = kind == RecurrentCellKernel::Kind::kLstm;
  at::Tensor h = at::randn({rows, kHidden}) * 0.5;
  at::Tensor c = at::randn({rows, kHidden}) * 0.5;
  // The kernel's rows: the hidden state, then an LSTM's cell state.
  const int64_t width = kernel->state_size();
  ASSERT_EQ(width, lstm ? 2 * kHidden : kHidden);
  std::vector<float> states = Floats(lstm ? at::cat({h, c}, 1) : h);
  torch::NoGradGuard no_grad;
  for (int step = 0; step < kSteps; ++step) {
    const at::Tensor x = at::randn({rows, kInputs}) * 2.0;
    // Every 7th step a row's episode starts: its state is zeroed on both
    // sides.
    if (step % 7 == 3) {
      const int64_t row = step % rows;
      h[row].zero_();
      c[row].zero_();
      std::memset(states.data() + row * width, 0, width * sizeof(float));
    }
    if constexpr (std::is_same_v<Cell, torch::nn::LSTMCell>) {
      std::tie(h, c) = cell->forward(x, std::make_tuple(h, c));
    } else {
      h = cell->forward(x, h);
    }
    kernel->Step(Floats(x).data(), rows, states.data());
    const std::vector<float> expected = Floats(h);
    const std::vector<float> expected_cell = Floats(c);
    for (int64_t r = 0; r < rows; ++r) {
      for (int64_t j = 0; j < kHidden; ++j) {
        ASSERT_NEAR(states[r * width + j], expected[r * kHidden + j], 2e-5)
            << "step " << step << " rows " << rows << " at " << r << "," << j;
        if (lstm) {
          ASSERT_NEAR(states[r * width + kHidden + j],
                      expected_cell[r * kHidden + j], 5e-5)
              << "cell, step " << step << " rows " << rows << " at " << r << ","
              << j;
        }
      }
    }
  }
}

TEST(RecurrentCellKernelTest, AGruStepsAsLibTorchsCell) {
  at::manual_seed(1);
  torch::nn::GRUCell cell(kInputs, kHidden);
  for (int64_t rows : {1, 3, 16}) {
    ExpectAgreement(RecurrentCellKernel::Kind::kGru, cell, rows);
  }
}

TEST(RecurrentCellKernelTest, AnLstmStepsAsLibTorchsCell) {
  at::manual_seed(2);
  torch::nn::LSTMCell cell(kInputs, kHidden);
  for (int64_t rows : {1, 3, 16}) {
    ExpectAgreement(RecurrentCellKernel::Kind::kLstm, cell, rows);
  }
}

TEST(RecurrentCellKernelTest, ShapesThatAreNoCellAreRefused) {
  const absl::Status status =
      RecurrentCellKernel::Create(RecurrentCellKernel::Kind::kLstm,
                                  at::zeros({12, 5}), at::zeros({12, 4}),
                                  at::zeros({12}), at::zeros({12}))
          .status();
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(status.message().find("LSTM cell needs weight_ih [4H, I]"),
            absl::string_view::npos)
      << status;
}

}  // namespace
}  // namespace vantage
