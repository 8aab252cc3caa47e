#include "learner/algorithms/trpo/trpo_updater.h"

#include <ATen/ATen.h>
#include <torch/csrc/autograd/autograd.h>
#include <torch/nn/utils/convert_parameters.h>
#include <torch/optim/adam.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "common/nn/distributions.h"
#include "learner/algorithms/gradient_step.h"
#include "learner/algorithms/trpo/conjugate_gradient.h"
#include "learner/parallel/replica_reductions.h"

namespace vantage {
namespace {

// Gradients of `parameters` as one vector; an unused parameter's is zero.
at::Tensor FlatGradient(const at::Tensor& output,
                        const std::vector<at::Tensor>& parameters,
                        bool create_graph) {
  const std::vector<at::Tensor> gradients = torch::autograd::grad(
      {output}, parameters, /*grad_outputs=*/{}, /*retain_graph=*/create_graph,
      create_graph, /*allow_unused=*/true);
  std::vector<at::Tensor> flat;
  flat.reserve(gradients.size());
  for (size_t i = 0; i < gradients.size(); ++i) {
    flat.push_back(gradients[i].defined() ? gradients[i].reshape({-1})
                                          : at::zeros({parameters[i].numel()},
                                                      parameters[i].options()));
  }
  return at::cat(flat);
}

// Writes `flat` into the parameters in place (they stay the same tensors,
// so the published weights and the module keep referring to them).
void AssignParameters(const at::Tensor& flat,
                      const std::vector<at::Tensor>& parameters) {
  at::NoGradGuard no_grad;
  int64_t offset = 0;
  for (const at::Tensor& p : parameters) {
    const int64_t n = p.numel();
    p.copy_(flat.slice(0, offset, offset + n).view_as(p));
    offset += n;
  }
}

// Every replica's batch is the same size, so means over the global batch
// are means of the replicas' means.
std::vector<double> MeansAcrossReplicas(ReplicaGroup& replicas,
                                        std::vector<double> local) {
  std::vector<double> sums = SumAcrossReplicas(replicas, std::move(local));
  for (double& sum : sums) sum /= replicas.world_size();
  return sums;
}

}  // namespace

TrpoUpdater::TrpoUpdater(PolicyNetwork policy, ValueNetwork value,
                         const TrpoConfig& config,
                         std::shared_ptr<ReplicaGroup> replicas)
    : PolicyUpdater(std::move(policy), std::move(value), std::move(replicas)),
      config_(config),
      policy_parameters_(policy_->parameters()),
      value_parameters_(value_->parameters()),
      value_optimizer_(std::make_unique<torch::optim::Adam>(
          value_parameters_,
          torch::optim::AdamOptions(config.value_learning_rate))) {}

TrpoUpdater::~TrpoUpdater() = default;

AlgorithmStats TrpoUpdater::Update(const UpdateBatch& batch,
                                   double /*progress*/, std::mt19937_64& rng) {
  at::Tensor advantages = batch.advantages;
  if (config_.normalize_advantages) {
    advantages = NormalizeAcrossReplicas(*replicas_, advantages);
  }
  AlgorithmStats stats;
  stats.clip_fraction = std::numeric_limits<double>::quiet_NaN();
  stats.max_gradient_norm = std::numeric_limits<double>::quiet_NaN();
  {
    at::NoGradGuard no_grad;
    stats.entropy = policy_->Entropy(Outputs(batch)).mean().item<double>();
  }
  double surrogate = 0.0;
  stats.approx_kl = PolicyStep(batch, advantages, surrogate);
  stats.policy_loss = -surrogate;
  // The linear baseline is the learner's, fitted (and its loss reported)
  // once the update is kept; the zero baseline fits nothing.
  stats.value_loss = config_.linear_baseline || config_.zero_baseline
                         ? 0.0
                         : FitValue(batch, rng);
  return stats;
}

double TrpoUpdater::PolicyStep(const UpdateBatch& batch,
                               const at::Tensor& advantages,
                               double& surrogate_after) {
  PolicyStepInputs step{batch, advantages, at::Tensor(), at::Tensor()};
  {
    at::NoGradGuard no_grad;
    step.old_output = Outputs(batch);
    if (!policy_->discrete()) step.old_log_std = policy_->log_std().clone();
  }
  const at::Tensor objective = Surrogate(step);
  const double objective_before =
      MeansAcrossReplicas(*replicas_, {objective.item<double>()})[0];
  surrogate_after = objective_before;
  const at::Tensor full_step = NaturalGradientStep(step, objective);
  if (!full_step.defined()) return 0.0;
  return LineSearch(step, full_step, objective_before, surrogate_after);
}

at::Tensor TrpoUpdater::Outputs(const UpdateBatch& batch) {
  return MaskLogits(policy_->forward(batch.observations), batch.action_masks);
}

at::Tensor TrpoUpdater::Surrogate(const PolicyStepInputs& step) {
  PolicyNetworkImpl& policy = *policy_;
  const at::Tensor output = Outputs(step.batch);
  const at::Tensor ratio = at::exp(policy.LogProb(output, step.batch.actions) -
                                   step.batch.behaviour_log_probs);
  return (ratio * step.advantages).mean() +
         config_.entropy_coef * policy.Entropy(output).mean();
}

at::Tensor TrpoUpdater::MeanKl(const PolicyStepInputs& step) {
  PolicyNetworkImpl& policy = *policy_;
  return policy.Kl(step.old_output, step.old_log_std, Outputs(step.batch))
      .mean();
}

at::Tensor TrpoUpdater::FisherProduct(const PolicyStepInputs& step,
                                      const at::Tensor& v) {
  const at::Tensor kl = MeanKl(step);
  const at::Tensor kl_gradient =
      FlatGradient(kl, policy_parameters_, /*create_graph=*/true);
  const at::Tensor product =
      FlatGradient((kl_gradient * v.detach()).sum(), policy_parameters_,
                   /*create_graph=*/false);
  return AverageAcrossReplicas(*replicas_, product.detach()) +
         config_.cg_damping * v;
}

at::Tensor TrpoUpdater::NaturalGradientStep(const PolicyStepInputs& step,
                                            const at::Tensor& objective) {
  const at::Tensor gradient = AverageAcrossReplicas(
      *replicas_,
      FlatGradient(objective, policy_parameters_, /*create_graph=*/false));
  auto fisher_product = [&](const at::Tensor& v) {
    return FisherProduct(step, v);
  };
  const at::Tensor direction = ConjugateGradient(
      fisher_product, gradient.detach(), config_.cg_iterations);
  const double curvature =
      0.5 * (direction * fisher_product(direction)).sum().item<double>();
  if (!(curvature > 0) || !std::isfinite(curvature)) return at::Tensor();
  return direction * std::sqrt(config_.max_kl / curvature);
}

double TrpoUpdater::LineSearch(const PolicyStepInputs& step,
                               const at::Tensor& full_step,
                               double objective_before,
                               double& surrogate_after) {
  const at::Tensor start =
      torch::nn::utils::parameters_to_vector(policy_parameters_)
          .detach()
          .clone();
  at::NoGradGuard no_grad;
  double fraction = 1.0;
  for (int i = 0; i < config_.line_search_steps; ++i, fraction *= 0.5) {
    AssignParameters(start + fraction * full_step, policy_parameters_);
    const std::vector<double> means = MeansAcrossReplicas(
        *replicas_,
        {Surrogate(step).item<double>(), MeanKl(step).item<double>()});
    const double value = means[0];
    const double kl = means[1];
    if (std::isfinite(value) && std::isfinite(kl) && kl <= config_.max_kl &&
        value > objective_before) {
      surrogate_after = value;
      return kl;
    }
  }
  AssignParameters(start, policy_parameters_);
  return 0.0;
}

double TrpoUpdater::FitValue(const UpdateBatch& batch, std::mt19937_64& rng) {
  const int64_t size = batch.observations.size(0);
  // The global minibatch is value_minibatch_size samples, shared out.
  const int64_t minibatch =
      std::min<int64_t>(std::max<int64_t>(1, config_.value_minibatch_size /
                                                 replicas_->world_size()),
                        size);
  std::vector<int64_t> order(size);
  double total = 0.0;
  int64_t count = 0;
  for (int epoch = 0; epoch < config_.value_epochs; ++epoch) {
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), rng);
    const at::Tensor permutation = at::tensor(order, at::kLong);
    for (int64_t begin = 0; begin + minibatch <= size; begin += minibatch) {
      const at::Tensor index = permutation.slice(0, begin, begin + minibatch);
      const at::Tensor loss =
          ValueLoss(*value_, batch.observations.index_select(0, index),
                    batch.returns.index_select(0, index));
      value_optimizer_->zero_grad();
      loss.backward();
      AverageGradients(*replicas_, value_parameters_);
      value_optimizer_->step();
      total += loss.item<double>();
      ++count;
    }
  }
  return count > 0 ? total / count : 0.0;
}

void TrpoUpdater::Save(torch::serialize::OutputArchive& archive) const {
  SaveOptimizer(*value_optimizer_, "value_adam", archive);
}

absl::Status TrpoUpdater::Load(torch::serialize::InputArchive& archive) {
  return LoadOptimizer(*value_optimizer_, "value_adam", archive);
}

}  // namespace vantage
