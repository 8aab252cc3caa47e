#include "learner/algorithms/a2c/flat_rmsprop.h"

#include <ATen/ATen.h>
#include <torch/optim/rmsprop.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "learner/algorithms/a2c/tensorflow_rmsprop.h"

namespace vantage {
namespace {

std::unique_ptr<torch::optim::Optimizer> MakeOptimizer(
    std::vector<at::Tensor> parameters, RmspropArithmetic arithmetic) {
  const auto options = torch::optim::RMSpropOptions(7e-4).alpha(0.99).eps(1e-5);
  if (arithmetic == RmspropArithmetic::kPytorch) {
    return std::make_unique<torch::optim::RMSprop>(parameters, options);
  }
  return std::make_unique<TensorflowRmsprop>(parameters, options);
}

// The largest difference over the reference's largest magnitude.
double RelativeError(const float* flat, const at::Tensor& reference) {
  const at::Tensor expected = reference.detach().contiguous().reshape(-1);
  const at::Tensor got =
      at::from_blob(const_cast<float*>(flat), {expected.numel()});
  return (got - expected).abs().max().item<double>() /
         std::max(1e-12, expected.abs().max().item<double>());
}

class FlatRmspropTest : public ::testing::TestWithParam<RmspropArithmetic> {};

TEST_P(FlatRmspropTest, StepsAsTheTorchOptimiserAndCarriesItsState) {
  at::manual_seed(6);
  std::vector<at::Tensor> reference = {at::randn({4, 3}), at::randn({5})};
  std::vector<at::Tensor> tensors = {reference[0].clone(),
                                     reference[1].clone()};
  for (at::Tensor& t : reference) t.set_requires_grad(true);
  auto torch_rmsprop = MakeOptimizer(reference, GetParam());
  auto holder = MakeOptimizer(tensors, GetParam());
  FlatRmsprop flat(tensors, {0, 12}, 17, GetParam());
  std::vector<float> values(17), gradients(17);
  std::copy_n(tensors[0].data_ptr<float>(), 12, values.begin());
  std::copy_n(tensors[1].data_ptr<float>(), 5, values.begin() + 12);
  for (int step = 0; step < 25; ++step) {
    // Gradients from tiny to large, where the arithmetics differ most.
    const at::Tensor g0 = at::randn({4, 3}) * (step % 3 == 0 ? 1e-4 : 3.0);
    const at::Tensor g1 = at::randn({5});
    reference[0].mutable_grad() = g0.clone();
    reference[1].mutable_grad() = g1.clone();
    torch_rmsprop->step();
    std::copy_n(g0.data_ptr<float>(), 12, gradients.begin());
    std::copy_n(g1.data_ptr<float>(), 5, gradients.begin() + 12);
    flat.Step(*holder, values.data(), gradients.data());
  }
  EXPECT_LE(RelativeError(values.data(), reference[0]), 1e-6);
  EXPECT_LE(RelativeError(values.data() + 12, reference[1]), 1e-6);

  // Through the torch optimiser's state and back, nothing changes.
  flat.StoreInto(*holder);
  FlatRmsprop restored(tensors, {0, 12}, 17, GetParam());
  ASSERT_TRUE(restored.LoadFrom(*holder).ok());
  std::vector<float> a = values, b = values;
  for (float& g : gradients) g = 0.25f;
  flat.Step(*holder, a.data(), gradients.data());
  restored.Step(*holder, b.data(), gradients.data());
  EXPECT_EQ(a, b);

  // The torch optimiser's state, stepped on, resumes the flat one exactly
  // as it would have gone on.
  std::copy_n(b.data(), 12, tensors[0].data_ptr<float>());
  std::copy_n(b.data() + 12, 5, tensors[1].data_ptr<float>());
  restored.StoreInto(*holder);
  tensors[0].mutable_grad() = at::full({4, 3}, 0.25f);
  tensors[1].mutable_grad() = at::full({5}, 0.25f);
  {
    at::NoGradGuard no_grad;
    holder->step();
  }
  restored.Step(*holder, b.data(), gradients.data());
  EXPECT_LE(RelativeError(b.data(), tensors[0]), 1e-6);
  EXPECT_LE(RelativeError(b.data() + 12, tensors[1]), 1e-6);
}

TEST_P(FlatRmspropTest, RefusesAStateThatDoesNotFit) {
  std::vector<at::Tensor> tensors = {at::randn({4, 3}), at::randn({5})};
  auto holder = MakeOptimizer(tensors, GetParam());
  FlatRmsprop flat(tensors, {0, 12}, 17, GetParam());
  std::vector<float> values(17, 0.5f), gradients(17, 1.0f);
  flat.Step(*holder, values.data(), gradients.data());
  flat.StoreInto(*holder);
  auto& state = static_cast<torch::optim::RMSpropParamState&>(
      *holder->state().begin()->second);
  state.square_avg(at::ones({2}));
  EXPECT_THAT(std::string(flat.LoadFrom(*holder).message()),
              ::testing::HasSubstr("does not fit its"));
  flat.StoreInto(*holder);
  static_cast<torch::optim::RMSpropParamState&>(
      *holder->state().begin()->second)
      .step(3);
  EXPECT_THAT(std::string(flat.LoadFrom(*holder).message()),
              ::testing::HasSubstr("took different numbers of steps"));
}

INSTANTIATE_TEST_SUITE_P(Arithmetics, FlatRmspropTest,
                         ::testing::Values(RmspropArithmetic::kPytorch,
                                           RmspropArithmetic::kTensorflow));

}  // namespace
}  // namespace vantage
