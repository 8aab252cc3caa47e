// Exported policies under an independent runtime, OpenCV's DNN module: on
// 1,000 observations (some far enough out to be clipped by the
// normaliser), its actions and distribution parameters agree with
// vantage's own forward pass within 1e-5 relative, for an MLP policy of
// each head and a convolutional one on byte frames.

#include "deploy/export/policy_onnx.h"

#include <ATen/ATen.h>

#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <string>
#include <vector>

#include "common/nn/distributions.h"
#include "common/nn/networks.h"
#include "common/nn/running_mean_std.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/fakes/random_policy.h"
#include "tests/fakes/vector_spec.h"

namespace vantage {
namespace {

constexpr int64_t kRows = 1000;
constexpr double kClip = 5.0;

// The model's outputs `names` for `observations` [kRows, obs] (float) and,
// for masked actions, `masks` [kRows, n] (bool).
std::vector<cv::Mat> RunOnOpenCv(const std::string& model,
                                 const at::Tensor& observations,
                                 const std::vector<std::string>& names,
                                 const at::Tensor& masks = at::Tensor()) {
  cv::dnn::Net net =
      cv::dnn::readNetFromONNX(std::vector<uchar>(model.begin(), model.end()));
  const at::Tensor input = observations.to(at::kFloat).contiguous();
  cv::Mat blob(static_cast<int>(input.size(0)), static_cast<int>(input.size(1)),
               CV_32F, input.data_ptr<float>());
  net.setInput(blob, "observation");
  const at::Tensor mask_values =
      masks.defined() ? masks.to(at::kFloat).contiguous() : at::Tensor();
  if (masks.defined()) {
    net.setInput(cv::Mat(static_cast<int>(masks.size(0)),
                         static_cast<int>(masks.size(1)), CV_32F,
                         mask_values.data_ptr<float>()),
                 "action_mask");
  }
  std::vector<cv::Mat> outputs;
  net.forward(outputs, std::vector<cv::String>(names.begin(), names.end()));
  return outputs;
}

// Every value within 1e-5 of the expected one's magnitude (at least 1).
void ExpectClose(const cv::Mat& got, const at::Tensor& want,
                 const std::string& what) {
  cv::Mat values;
  got.convertTo(values, CV_32F);
  const at::Tensor expected = want.to(at::kFloat).contiguous().reshape(-1);
  ASSERT_EQ(static_cast<int64_t>(values.total()), expected.numel()) << what;
  const float* data = values.ptr<float>();
  double worst = 0.0;
  for (int64_t i = 0; i < expected.numel(); ++i) {
    const double e = expected[i].item<float>();
    worst = std::max(worst, std::abs(data[i] - e) / std::max(1.0, std::abs(e)));
  }
  EXPECT_LE(worst, 1e-5) << what;
}

struct Exported {
  EnvSpec spec;
  PolicyNetwork policy{nullptr};
  RunningMeanStd normalizer{1};
  std::string model;
  at::Tensor observations;  // as the environment gives them
  at::Tensor output;        // vantage's forward pass: means or logits
};

// `clip` infinite: a run that does not normalise its observations (its
// normaliser keeps the initial statistics).
Exported Export(const EnvSpec& spec, const NetworkConfig& config,
                double clip = kClip) {
  Exported e;
  e.spec = spec;
  e.policy = PolicyNetwork(spec, config);
  e.normalizer = RunningMeanStd(spec.observation_size);
  RandomisePolicy(*e.policy, e.normalizer, spec);
  if (std::isinf(clip)) e.normalizer = RunningMeanStd(spec.observation_size);
  OnnxExportOptions options;
  options.distribution = true;
  absl::StatusOr<std::string> model =
      PolicyToOnnx(spec, *e.policy, e.normalizer, clip, options);
  EXPECT_TRUE(model.ok()) << model.status();
  if (model.ok()) e.model = *model;
  e.observations =
      spec.byte_observations()
          ? at::randint(0, spec.observation_high + 1,
                        {kRows, spec.observation_size}, at::kDouble)
          : at::randn({kRows, spec.observation_size}, at::kDouble) * 4.0;
  at::NoGradGuard no_grad;
  e.output = e.policy->forward(ObservationsForNetwork(
      spec, e.normalizer,
      ObservationTensor(spec, e.observations.data_ptr<double>(), kRows), clip));
  return e;
}

TEST(PolicyOnnxTest, AGaussianMlpPolicyAgreesUnderOpenCv) {
  at::manual_seed(1);
  EnvSpec spec = VectorSpec(false, 17, 6);
  spec.action_low = {-1, -1, -0.5, -2, -std::numeric_limits<double>::infinity(),
                     -1};
  spec.action_high = {1, 1, 0.5, 2, std::numeric_limits<double>::infinity(), 1};
  const Exported e = Export(spec, NetworkConfig());
  const std::vector<cv::Mat> out =
      RunOnOpenCv(e.model, e.observations, {"action", "mean", "log_std"});
  ASSERT_EQ(out.size(), 3u);
  const at::Tensor low = at::tensor(spec.action_low).to(at::kFloat);
  const at::Tensor high = at::tensor(spec.action_high).to(at::kFloat);
  ExpectClose(out[0], at::max(at::min(e.output, high), low), "action");
  ExpectClose(out[1], e.output, "mean");
  ExpectClose(out[2], e.policy->log_std().expand({kRows, 6}), "log_std");
}

// Without normalisation nothing is clipped: observations far beyond any
// clip reach the network as they are, in the export as in vantage.
TEST(PolicyOnnxTest, AnUnnormalisedPolicyAgreesUnderOpenCv) {
  at::manual_seed(4);
  const EnvSpec spec = VectorSpec(false, 5, 2);
  Exported e =
      Export(spec, NetworkConfig(), std::numeric_limits<double>::infinity());
  EXPECT_EQ(e.model.find("Clip"), std::string::npos);
  const at::Tensor wide = e.observations * 10.0;
  at::NoGradGuard no_grad;
  const at::Tensor raw =
      ObservationTensor(spec, wide.data_ptr<double>(), kRows);
  const at::Tensor want = e.policy->forward(raw);
  // A clip at kClip would have changed them.
  EXPECT_FALSE(at::allclose(want, e.policy->forward(ObservationsForNetwork(
                                      spec, e.normalizer, raw, kClip))));
  const std::vector<cv::Mat> out = RunOnOpenCv(e.model, wide, {"mean"});
  ASSERT_EQ(out.size(), 1u);
  ExpectClose(out[0], want, "mean");
}

TEST(PolicyOnnxTest, ACategoricalMlpPolicyAgreesUnderOpenCv) {
  at::manual_seed(2);
  NetworkConfig config;
  config.hidden = {32, 16};
  const Exported e = Export(VectorSpec(true, 11, 5), config);
  const std::vector<cv::Mat> out =
      RunOnOpenCv(e.model, e.observations, {"action", "logits"});
  ASSERT_EQ(out.size(), 2u);
  ExpectClose(out[0], e.output.argmax(-1), "action");
  ExpectClose(out[1], e.output, "logits");
}

// Masked actions: the model takes the masks as a second input and acts,
// and gives logits, as vantage does under them.
TEST(PolicyOnnxTest, AMaskedCategoricalPolicyAgreesUnderOpenCv) {
  at::manual_seed(4);
  EnvSpec spec = VectorSpec(true, 11, 6);
  spec.action_masks = true;
  const Exported e = Export(spec, NetworkConfig());
  at::Tensor masks = at::rand({kRows, 6}) < 0.3;
  masks.select(1, 2).fill_(true);  // a legal action in every row
  const at::Tensor masked = MaskLogits(e.output, masks);
  const std::vector<cv::Mat> out =
      RunOnOpenCv(e.model, e.observations, {"action", "logits"}, masks);
  ASSERT_EQ(out.size(), 2u);
  ExpectClose(out[0], masked.argmax(-1), "action");
  ExpectClose(out[1], masked, "logits");
  // The masks decide: the unmasked argmax is illegal in many rows.
  EXPECT_GT(masks.gather(1, e.output.argmax(-1, true))
                .logical_not()
                .sum()
                .item<int64_t>(),
            kRows / 4);
}

// MultiDiscrete (3 heads of 4, 2 and 5 choices): each head's most likely
// choice, side by side, as vantage's deterministic action.
TEST(PolicyOnnxTest, AMultiDiscretePolicyAgreesUnderOpenCv) {
  at::manual_seed(5);
  EnvSpec spec = VectorSpec(true, 9, 11);
  spec.action_nvec = {4, 2, 5};
  const Exported e = Export(spec, NetworkConfig());
  const std::vector<cv::Mat> out =
      RunOnOpenCv(e.model, e.observations, {"action", "logits"});
  ASSERT_EQ(out.size(), 2u);
  const at::Tensor heads = at::stack(
      {e.output.slice(1, 0, 4).argmax(1), e.output.slice(1, 4, 6).argmax(1),
       e.output.slice(1, 6, 11).argmax(1)},
      1);
  ExpectClose(out[0], heads, "action");
  ExpectClose(out[1], e.output, "logits");
}

// A Dict of a 2x6x6 camera and 5 joint values: the camera's slice of the
// row through its convolutional torso, the joints normalised.
TEST(PolicyOnnxTest, ADictPolicyAgreesUnderOpenCv) {
  at::manual_seed(6);
  EnvSpec spec = VectorSpec(true, 77, 4);
  spec.observation_keys = {{"camera", 72, {2, 6, 6}, 255},
                           {"joints", 5, {}, 0}};
  Exported e = Export(spec, NetworkConfig());
  // The camera's entries as an environment gives them: bytes.
  e.observations.slice(1, 0, 72).copy_(
      at::randint(0, 256, {kRows, 72}, at::kDouble));
  at::NoGradGuard no_grad;
  const at::Tensor output = e.policy->forward(ObservationsForNetwork(
      spec, e.normalizer,
      ObservationTensor(spec, e.observations.data_ptr<double>(), kRows),
      kClip));
  const std::vector<cv::Mat> out =
      RunOnOpenCv(e.model, e.observations, {"action", "logits"});
  ASSERT_EQ(out.size(), 2u);
  ExpectClose(out[0], output.argmax(-1), "action");
  ExpectClose(out[1], output, "logits");
}

TEST(PolicyOnnxTest, AConvolutionalPolicyOnBytesAgreesUnderOpenCv) {
  at::manual_seed(3);
  EnvSpec spec = VectorSpec(true, 4 * 10 * 10, 3);
  spec.observation_shape = {4, 10, 10};
  spec.observation_high = 1;
  NetworkConfig config;
  config.torso = Torso::kMinAtar;
  const Exported e = Export(spec, config);
  const std::vector<cv::Mat> out =
      RunOnOpenCv(e.model, e.observations, {"action", "logits"});
  ASSERT_EQ(out.size(), 2u);
  ExpectClose(out[0], e.output.argmax(-1), "action");
  ExpectClose(out[1], e.output, "logits");
}

TEST(PolicyOnnxTest, ARecurrentPolicyIsRefusedByName) {
  const EnvSpec spec = VectorSpec(false, 5, 2);
  NetworkConfig config;
  config.core = Core::kLstm;
  PolicyNetwork policy(spec, config);
  const absl::Status status =
      PolicyToOnnx(spec, *policy, RunningMeanStd(5), kClip, {}).status();
  EXPECT_EQ(status.code(), absl::StatusCode::kUnimplemented);
  EXPECT_THAT(std::string(status.message()),
              ::testing::HasSubstr("the policy has a recurrent core (lstm)"));
}

}  // namespace
}  // namespace vantage
