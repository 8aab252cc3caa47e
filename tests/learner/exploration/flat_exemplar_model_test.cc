#include "learner/exploration/flat_exemplar_model.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>

#include <algorithm>
#include <vector>

#include "gtest/gtest.h"
#include "learner/exploration/exemplar_model.h"

namespace vantage {
namespace {

// Two hidden sizes, so that every MLP has a hidden tanh layer between two
// others and the trunk's width differs from the heads'.
Ex2Config TwoLayerConfig() {
  Ex2Config config;
  config.hidden = {7, 5};
  config.feature_dim = 3;
  return config;
}

std::vector<float> Flatten(const std::vector<at::Tensor>& parameters) {
  std::vector<float> flat;
  for (const at::Tensor& p : parameters) {
    const at::Tensor values = p.detach().contiguous();
    flat.insert(flat.end(), values.data_ptr<float>(),
                values.data_ptr<float>() + values.numel());
  }
  return flat;
}

// The flat loss and gradient against autograd's on the same model, pairs
// and noise: the loss to 1e-5, every gradient to 1e-4 of its tensor's
// largest entry (or of `scale_floor` if that is larger), the accuracy
// exactly, and the noise generators left in the same state.
void ExpectFlatMatchesAutograd(ExemplarModelImpl& model,
                               const Ex2Config& config,
                               const at::Tensor& positives,
                               const at::Tensor& negatives, double kl_weight,
                               double scale_floor = 1e-6) {
  const std::vector<at::Tensor> parameters = model.parameters();
  absl::StatusOr<FlatExemplarModel> flat =
      FlatExemplarModel::Create(model, config, parameters);
  ASSERT_TRUE(flat.ok()) << flat.status();
  std::vector<float> flat_parameters = Flatten(parameters);
  ASSERT_EQ(static_cast<int64_t>(flat_parameters.size()), flat->size());
  std::vector<float> gradients(flat->size(), -7.0f);

  at::Generator autograd_noise = at::make_generator<at::CPUGeneratorImpl>(11);
  at::Generator flat_noise = at::make_generator<at::CPUGeneratorImpl>(11);
  for (const at::Tensor& p : parameters) p.mutable_grad().reset();
  const ExemplarLoss reference = ComputeExemplarLoss(
      model, positives, negatives, kl_weight, autograd_noise);
  reference.loss.backward();
  const FlatExemplarLoss got =
      flat->LossAndGradient(flat_parameters.data(), positives, negatives,
                            kl_weight, flat_noise, gradients.data());

  const double loss = reference.loss.item<double>();
  EXPECT_NEAR(got.loss, loss, 1e-5 * std::max(1.0, std::abs(loss)));
  EXPECT_EQ(got.accuracy, reference.accuracy);
  int64_t offset = 0;
  for (size_t i = 0; i < parameters.size(); ++i) {
    const at::Tensor expected = parameters[i].grad().reshape({-1});
    const at::Tensor actual =
        at::from_blob(gradients.data() + offset, {parameters[i].numel()})
            .clone();
    const double scale =
        std::max(scale_floor, expected.abs().max().item<double>());
    EXPECT_LE((actual - expected).abs().max().item<double>() / scale, 1e-4)
        << "parameter " << i << " of " << parameters.size();
    offset += parameters[i].numel();
  }
  EXPECT_EQ(at::randint(1 << 30, {1}, autograd_noise).item<int64_t>(),
            at::randint(1 << 30, {1}, flat_noise).item<int64_t>());
}

TEST(FlatExemplarModelTest, LossAndGradientsAreAutogradsWithTheSameNoise) {
  const Ex2Config config = TwoLayerConfig();
  at::manual_seed(3);
  ExemplarModel model(4, config);
  const at::Tensor positives = at::randn({9, 4});
  const at::Tensor negatives = at::randn({9, 4}) * 2 + 1;
  ExpectFlatMatchesAutograd(*model, config, positives, negatives, 0.3);
  // EX2's own shape: one hidden size, 128 pairs.
  Ex2Config reference_config;
  reference_config.hidden = {32};
  reference_config.feature_dim = 16;
  ExemplarModel wide(23, reference_config);
  ExpectFlatMatchesAutograd(*wide, reference_config, at::randn({128, 23}),
                            at::randn({128, 23}), 0.1);
}

// Where D is clipped (to [1e-6, 1 - 1e-6]) the loss has no gradient
// through it: a discriminator scaled up until most pairs saturate still
// agrees with autograd, whose clamp passes none. A clipped pair that
// passed its gradient would add about 1 / 32 to the output bias's; the
// pairs left unclipped are so near saturation that their gradients (about
// 1e-6 in all) are held to 1e-4 of 1e-3: the sigmoid's rounding there is
// larger than 1e-4 of them.
TEST(FlatExemplarModelTest, ClippedProbabilitiesPassNoGradient) {
  const Ex2Config config = TwoLayerConfig();
  at::manual_seed(4);
  ExemplarModel model(4, config);
  {
    at::NoGradGuard no_grad;
    for (at::Tensor& p : model->discriminator()->parameters()) p.mul_(40.0);
  }
  const at::Tensor positives = at::randn({16, 4}) * 3;
  const at::Tensor negatives = at::randn({16, 4}) * 3;
  const at::Tensor p =
      model->forward(positives, positives, nullptr).probability;
  ASSERT_GT(((p < 1e-6) | (p > 1 - 1e-6)).sum().item<int64_t>(), 0)
      << "the case needs clipped pairs";
  ExpectFlatMatchesAutograd(*model, config, positives, negatives, 0.01,
                            /*scale_floor=*/1e-3);
}

}  // namespace
}  // namespace vantage
