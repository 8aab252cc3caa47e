#ifndef VANTAGE_COMMON_NN_MLP_POLICY_KERNEL_H_
#define VANTAGE_COMMON_NN_MLP_POLICY_KERNEL_H_

// The policy of an MLP network as acting needs it, without LibTorch's
// per-operator dispatch: the weights of one published version laid out
// once as float arrays, the observation normaliser applied as the
// networks' inputs need it, each layer one BLAS call over all of an
// actor's environments, and sampling and log-probabilities in one pass
// that draws from the generator exactly as PolicyNetworkImpl::Act does.
// Its outputs agree with PolicyNetworkImpl's forward, Act and LogProb up
// to float rounding (tests/common/nn/mlp_policy_kernel_test.cc).

#include <ATen/core/Generator.h>

#include <cstdint>
#include <vector>

#include "absl/status/statusor.h"
#include "common/env/environment.h"

namespace vantage {

class PolicyNetworkImpl;
class RunningMeanStd;

class MlpPolicyKernel {
 public:
  // A copy of `policy` and `normalizer` as they are now (call again for
  // new weights). Unimplemented for a policy it cannot run (a
  // convolutional torso); acting then stays on LibTorch.
  static absl::StatusOr<MlpPolicyKernel> Create(
      const EnvSpec& spec, PolicyNetworkImpl& policy,
      const RunningMeanStd& normalizer, double observation_clip);

  // Means (continuous) or logits (discrete) per row.
  int64_t output_size() const { return output_size_; }
  // k action values per row, or 1 (the index, as a float) when discrete.
  int64_t action_width() const { return discrete_ ? 1 : output_size_; }

  // The network's outputs [rows, output_size] for `rows` observations as
  // the environments wrote them (doubles, [rows, observation_size]): what
  // policy.forward(ObservationsForNetwork(...)) gives for them stored in
  // the dtype segments hold.
  void Forward(const double* observations, int64_t rows, float* outputs);
  // From Forward's outputs: sampled actions [rows, action_width()] and
  // their log-probabilities [rows].
  void Act(const float* outputs, int64_t rows, at::Generator& generator,
           float* actions, float* log_probs);

 private:
  struct Layer {
    int64_t inputs = 0;
    int64_t outputs = 0;
    std::vector<float> weight;  // [outputs, inputs], row-major
    std::vector<float> bias;    // [outputs]
  };

  MlpPolicyKernel() = default;
  void Inputs(const double* observations, int64_t rows, float* inputs) const;

  EnvSpec spec_;
  bool discrete_ = false;
  int64_t output_size_ = 0;
  double clip_ = 0.0;
  std::vector<double> mean_;   // the normaliser's, [observation_size]
  std::vector<double> scale_;  // sqrt(var + 1e-8)
  std::vector<Layer> layers_;
  int64_t widest_ = 0;  // the widest of the inputs and every layer's outputs
  std::vector<float> log_std_;  // continuous only
  std::vector<float> std_;      // exp(log_std)
  std::vector<float> inv_std_;  // exp(-log_std)
  // Scratch, grown to the largest batch seen.
  std::vector<float> buffer_a_, buffer_b_, noise_, probabilities_;
  std::vector<float> row_max_, row_log_sum_;
  std::vector<int64_t> indices_;
};

}  // namespace vantage

#endif  // VANTAGE_COMMON_NN_MLP_POLICY_KERNEL_H_
