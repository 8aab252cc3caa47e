#include "learner/algorithms/gradient_step.h"

#include <ATen/ATen.h>
#include <torch/optim/adam.h>
#include <torch/optim/rmsprop.h>
#include <torch/serialize/archive.h>

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace vantage {
namespace {

using ::testing::HasSubstr;

// One step with unit gradients, so that every state tensor exists.
void StepOnce(torch::optim::Optimizer& optimizer,
              std::vector<at::Tensor>& parameters) {
  for (at::Tensor& parameter : parameters) {
    parameter.mutable_grad() = at::ones_like(parameter);
  }
  at::NoGradGuard no_grad;
  optimizer.step();
}

std::vector<at::Tensor> Parameters(std::vector<int64_t> first_shape) {
  std::vector<at::Tensor> parameters = {at::randn(first_shape), at::randn({5})};
  for (at::Tensor& parameter : parameters) parameter.set_requires_grad(true);
  return parameters;
}

std::unique_ptr<torch::optim::Optimizer> MakeOptimizer(
    const std::string& kind, const std::vector<at::Tensor>& parameters) {
  if (kind == "adam") {
    return std::make_unique<torch::optim::Adam>(
        parameters, torch::optim::AdamOptions(1e-3));
  }
  return std::make_unique<torch::optim::RMSprop>(
      parameters, torch::optim::RMSpropOptions(1e-3).momentum(0.9));
}

torch::serialize::InputArchive Reopened(
    torch::serialize::OutputArchive& archive) {
  std::stringstream bytes;
  archive.save_to(bytes);
  torch::serialize::InputArchive reopened;
  reopened.load_from(bytes);
  return reopened;
}

class LoadOptimizerTest : public ::testing::TestWithParam<std::string> {};

TEST_P(LoadOptimizerTest, AStateOfTheSameShapesLoads) {
  std::vector<at::Tensor> parameters = Parameters({4, 3});
  auto optimizer = MakeOptimizer(GetParam(), parameters);
  StepOnce(*optimizer, parameters);
  torch::serialize::OutputArchive archive;
  SaveOptimizer(*optimizer, "opt", archive);

  std::vector<at::Tensor> copy = {parameters[0].detach().clone(),
                                  parameters[1].detach().clone()};
  auto restored = MakeOptimizer(GetParam(), copy);
  torch::serialize::InputArchive input = Reopened(archive);
  ASSERT_TRUE(LoadOptimizer(*restored, "opt", input).ok());
  // The next step of both is the same: the state really was restored.
  StepOnce(*optimizer, parameters);
  StepOnce(*restored, copy);
  EXPECT_TRUE(at::allclose(parameters[0], copy[0]));
  EXPECT_TRUE(at::allclose(parameters[1], copy[1]));
}

// A state saved for networks of other sizes (the same number of
// parameters) is refused at load, naming the tensor and both shapes, and
// the optimiser keeps the state it had.
TEST_P(LoadOptimizerTest, AStateOfOtherShapesIsRefusedAtLoad) {
  std::vector<at::Tensor> other = Parameters({2, 6});
  auto saved_for_other = MakeOptimizer(GetParam(), other);
  StepOnce(*saved_for_other, other);
  torch::serialize::OutputArchive archive;
  SaveOptimizer(*saved_for_other, "opt", archive);

  std::vector<at::Tensor> parameters = Parameters({4, 3});
  auto optimizer = MakeOptimizer(GetParam(), parameters);
  StepOnce(*optimizer, parameters);
  std::vector<at::Tensor> twin = {parameters[0].detach().clone(),
                                  parameters[1].detach().clone()};
  auto reference = MakeOptimizer(GetParam(), twin);
  StepOnce(*reference, twin);
  for (size_t i = 0; i < twin.size(); ++i) {
    at::NoGradGuard no_grad;
    twin[i].copy_(parameters[i]);
  }

  torch::serialize::InputArchive input = Reopened(archive);
  const absl::Status status = LoadOptimizer(*optimizer, "opt", input);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  const std::string first = GetParam() == "adam" ? "exp_avg" : "square_avg";
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("optimiser state 'opt' does not fit: its " + first +
                        " of parameter 0 has shape [2, 6], the parameter "
                        "[4, 3]"));
  StepOnce(*optimizer, parameters);
  StepOnce(*reference, twin);
  EXPECT_TRUE(at::allclose(parameters[0], twin[0]));
  EXPECT_TRUE(at::allclose(parameters[1], twin[1]));
}

TEST_P(LoadOptimizerTest, AMissingStateIsRefused) {
  std::vector<at::Tensor> parameters = Parameters({4, 3});
  auto optimizer = MakeOptimizer(GetParam(), parameters);
  torch::serialize::OutputArchive archive;
  SaveOptimizer(*optimizer, "opt", archive);
  torch::serialize::InputArchive input = Reopened(archive);
  const absl::Status status = LoadOptimizer(*optimizer, "other", input);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(std::string(status.message()),
              HasSubstr("optimiser state 'other' is missing or does not fit"));
}

INSTANTIATE_TEST_SUITE_P(Optimizers, LoadOptimizerTest,
                         ::testing::Values("adam", "rmsprop"));

}  // namespace
}  // namespace vantage
