#ifndef VANTAGE_LEARNER_ALGORITHMS_FIRST_ORDER_UPDATER_H_
#define VANTAGE_LEARNER_ALGORITHMS_FIRST_ORDER_UPDATER_H_

#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "common/nn/networks.h"
#include "learner/algorithms/chunk_minibatches.h"
#include "learner/algorithms/flat_actor_critic.h"
#include "learner/algorithms/flat_optimizer.h"
#include "learner/algorithms/policy_updater.h"
#include "learner/parallel/replica_group.h"

namespace torch::optim {
class Optimizer;
}  // namespace torch::optim

namespace vantage {

// The loss coefficients and step settings PPO and A2C both have.
struct GradientSettings {
  double learning_rate = 3e-4;  // decayed linearly to 0 over the run
  double value_coef = 0.5;
  double entropy_coef = 0.0;
  double max_grad_norm = 0.5;
};

// A gradient-step algorithm's update (PPO, A2C): one optimiser over both
// networks' parameters whose learning rate decays linearly over the run,
// and for MLP networks its fused twin over FlatActorCritic's flat arrays
// (the same steps without autograd, several times faster); convolutional
// networks, or all when `autograd_only`, train through LibTorch's
// autograd. A derived algorithm computes each minibatch's loss and
// gradients with respect to log-probabilities and values; the gradient
// step and its statistics are this class's.
class FirstOrderUpdater : public PolicyUpdater {
 public:
  static constexpr bool kOneOptimizer = true;

  ~FirstOrderUpdater() override;

  AlgorithmStats Update(const UpdateBatch& batch, double progress,
                        std::mt19937_64& rng) final;
  void Save(torch::serialize::OutputArchive& archive) const final;
  absl::Status Load(torch::serialize::InputArchive& archive) final;

  // Whether updates bypass autograd.
  bool flat() const { return flat_.has_value(); }

 protected:
  // `algorithm` names it in the log line saying why the flat networks
  // cannot serve; `checkpoint_key` is the optimiser state's entry.
  FirstOrderUpdater(PolicyNetwork policy, ValueNetwork value,
                    std::shared_ptr<ReplicaGroup> replicas,
                    const GradientSettings& settings, const char* algorithm,
                    std::string checkpoint_key, bool autograd_only);

  // Called once by the derived constructor: the optimiser over
  // parameters(), and its fused twin when flat().
  void UseOptimizers(std::unique_ptr<torch::optim::Optimizer> optimizer,
                     std::unique_ptr<FlatOptimizer> flat_optimizer);

  // The update's minibatches on the flat networks or through autograd.
  virtual AlgorithmStats FlatUpdate(const UpdateBatch& batch,
                                    std::mt19937_64& rng) = 0;
  virtual AlgorithmStats AutogradUpdate(const UpdateBatch& batch,
                                        std::mt19937_64& rng) = 0;

  // The batch's columns as contiguous float rows, for the flat networks;
  // a recurrent policy's also the episode starts (uint8 per row) and the
  // chunks' start states.
  struct FlatRows {
    at::Tensor inputs, actions, behaviour, advantages, returns;
    at::Tensor masks;  // masked actions' uint8 [rows, actions]; else undefined
    at::Tensor starts, states;
    int64_t seq_len = 0;
  };
  // Pulls the modules' parameters into the flat networks (they may have
  // been rolled back or loaded since the last update) and lays out `batch`.
  FlatRows StartFlatUpdate(const UpdateBatch& batch);

  // The rows of `minibatch` (in its order) gathered from `rows`, and the
  // flat networks' forward pass on them: over its chunks for a recurrent
  // policy. Valid until the next call.
  struct Gathered {
    int64_t rows = 0;
    const float* behaviour = nullptr;
    float* advantages = nullptr;  // the caller's to normalise or weight
    const float* returns = nullptr;
  };
  Gathered GatherAndForward(const FlatRows& rows,
                            const ChunkMinibatch& minibatch);

  // A flat minibatch's loss sums over its rows.
  struct LossSums {
    double policy_loss = 0.0;
    double value_loss = 0.0;  // of 0.5 * error^2
    double approx_kl = 0.0;
  };
  // The gradient step after FlatActorCritic::Forward over `rows` rows with
  // d_log_probs() and d_values() filled: backward, the gradient averaged
  // over the replicas and clipped, the optimiser's step; the minibatch's
  // statistics with `clip_fraction` (NaN where nothing clips).
  AlgorithmStats FlatStep(int64_t rows, const LossSums& sums,
                          double clip_fraction);
  // The same through autograd: one step on policy_loss + value_coef *
  // value_loss - entropy_coef * entropy. approx_kl and clip_fraction are
  // the caller's to fill.
  AlgorithmStats AutogradStep(const at::Tensor& policy_loss,
                              const at::Tensor& value_loss,
                              const at::Tensor& entropy);

  // The policy's outputs and the critic's values on a minibatch's rows of
  // `batch`: a recurrent policy's through its trunk over the minibatch's
  // chunks, a feed-forward one's (`chunks` undefined) row by row.
  ChunkOutputs Evaluate(const UpdateBatch& batch,
                        const ChunkMinibatch& minibatch);

  // d(loss)/d(value) for a row whose value misses its target by `error`,
  // in a minibatch of `rows` rows.
  float ValueGradient(float error, double rows) const {
    return static_cast<float>(settings_.value_coef * error / rows);
  }
  // Scratch the derived FlatUpdate fills for FlatStep, `rows` long.
  float* d_log_probs(int64_t rows);
  float* d_values(int64_t rows);

  const std::vector<at::Tensor>& parameters() const { return parameters_; }
  FlatActorCritic& flat_networks() { return *flat_; }

 private:
  const GradientSettings settings_;
  const std::string checkpoint_key_;
  std::vector<at::Tensor> parameters_;
  std::unique_ptr<torch::optim::Optimizer> optimizer_;
  std::optional<FlatActorCritic> flat_;
  std::unique_ptr<FlatOptimizer> flat_optimizer_;
  std::vector<float> d_log_probs_, d_values_;
  // Scratch of GatherAndForward: one minibatch's rows.
  std::vector<float> inputs_, actions_, behaviour_, advantages_, returns_,
      states_;
  std::vector<uint8_t> starts_, masks_;
};

}  // namespace vantage

#endif  // VANTAGE_LEARNER_ALGORITHMS_FIRST_ORDER_UPDATER_H_
