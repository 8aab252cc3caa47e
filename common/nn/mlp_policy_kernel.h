#ifndef VANTAGE_COMMON_NN_MLP_POLICY_KERNEL_H_
#define VANTAGE_COMMON_NN_MLP_POLICY_KERNEL_H_

// The policy of an MLP network as acting needs it, without LibTorch's
// per-operator dispatch: the weights of one published version laid out
// once as float arrays, the observation normaliser applied as the
// networks' inputs need it, each layer one BLAS call over all of an
// actor's environments, and sampling and log-probabilities in one pass
// that draws from the generator exactly as PolicyNetworkImpl::Act does.
// A recurrent core after the MLP (NetworkConfig::core) steps through
// RecurrentCellKernel, its gates two BLAS calls over all environments.
// Its outputs agree with PolicyNetworkImpl's forward (or Step), Act and
// LogProb up to float rounding (tests/common/nn/mlp_policy_kernel_test.cc).

#include <ATen/core/Generator.h>

#include <cstdint>
#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "common/env/environment.h"
#include "common/nn/recurrent_cell_kernel.h"

namespace torch::nn {
class ModuleList;
}  // namespace torch::nn

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
  // k action values per row, or one index (as a float) per discrete head.
  int64_t action_width() const {
    return discrete_ ? static_cast<int64_t>(heads_.size()) : output_size_;
  }
  // The discrete heads' choices (EnvSpec::action_heads).
  const std::vector<int64_t>& heads() const { return heads_; }

  // Floats per row of a recurrent policy's state; 0 for a feed-forward one.
  int64_t state_size() const {
    return cell_.has_value() ? cell_->state_size() : 0;
  }

  // The network's outputs [rows, output_size] for `rows` observations as
  // the environments wrote them (doubles, [rows, observation_size]): what
  // policy.forward(ObservationsForNetwork(...)) gives for them stored in
  // the dtype segments hold. A recurrent policy reads and overwrites
  // `states` [rows, state_size()] as PolicyNetworkImpl::Step does.
  void Forward(const double* observations, int64_t rows, float* outputs,
               float* states = nullptr);
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
  // Copies the Linear layers of `mlp`, whose inputs must be `width` wide;
  // `width` becomes their outputs.
  absl::Status AddLayers(const torch::nn::ModuleList& mlp, const char* name,
                         int64_t& width);
  absl::Status AddCore(PolicyNetworkImpl& policy, int64_t& width);
  void Inputs(const double* observations, int64_t rows, float* inputs) const;
  // y = x W^T + b for `rows` rows, tanh'd when `squash`.
  static void Apply(const Layer& layer, const float* x, int64_t rows,
                    bool squash, float* y);

  EnvSpec spec_;
  bool discrete_ = false;
  std::vector<int64_t> heads_;  // discrete only
  int64_t output_size_ = 0;
  double clip_ = 0.0;
  std::vector<double> mean_;   // the normaliser's, [observation_size]
  std::vector<double> scale_;  // sqrt(var + 1e-8)
  std::vector<Layer> layers_;
  // A recurrent policy's: its first encoder_layers_ layers (all tanh'd)
  // feed the cell, the rest read its hidden state.
  size_t encoder_layers_ = 0;
  std::optional<RecurrentCellKernel> cell_;
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
