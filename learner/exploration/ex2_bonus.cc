#include "learner/exploration/ex2_bonus.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <torch/optim/adam.h>
#include <torch/serialize/archive.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/nn/networks.h"
#include "learner/algorithms/gradient_step.h"
#include "learner/checkpoint/archive_io.h"

namespace vantage {
namespace {

int64_t InputWidth(const Ex2Config& config, const EnvSpec& spec) {
  return spec.observation_size + (config.use_actions ? spec.action_size : 0);
}

// Byte observations alone are pooled as the bytes they arrive in (scaled
// as the networks scale them when sampled); with actions, rows of floats.
int64_t PoolByteHigh(const Ex2Config& config, const EnvSpec& spec) {
  return spec.byte_observations() && !config.use_actions ? spec.observation_high
                                                         : 0;
}

// numpy's median: the mean of the two middle values of an even count.
double Median(const at::Tensor& values) {
  const at::Tensor sorted = std::get<0>(values.sort());
  const int64_t n = sorted.size(0);
  const double upper = sorted[n / 2].item<double>();
  return n % 2 == 1 ? upper : 0.5 * (upper + sorted[n / 2 - 1].item<double>());
}

}  // namespace

Ex2Bonus::Ex2Bonus(const Ex2Config& config, const EnvSpec& spec, uint64_t seed,
                   std::shared_ptr<ReplicaGroup> replicas, Ex2Fit fit)
    : config_(config),
      spec_(spec),
      replicas_(std::move(replicas)),
      model_(InputWidth(config, spec), config,
             config.convolutional() ? spec.observation_shape
                                    : std::vector<int64_t>{}),
      optimizer_(std::make_unique<torch::optim::Adam>(
          model_->parameters(),
          torch::optim::AdamOptions(config.learning_rate))),
      generator_(at::make_generator<at::CPUGeneratorImpl>(seed)),
      pool_(config.replay_size, InputWidth(config, spec),
            PoolByteHigh(config, spec)) {
  if (fit == Ex2Fit::kTorch) return;
  std::vector<at::Tensor> parameters = model_->parameters();
  std::vector<int64_t> offsets;
  int64_t size = 0;
  for (const at::Tensor& p : parameters) {
    offsets.push_back(size);
    size += p.numel();
  }
  flat_parameters_ = at::empty({size}, at::kFloat);
  at::NoGradGuard no_grad;
  for (size_t i = 0; i < parameters.size(); ++i) {
    at::Tensor view =
        flat_parameters_.narrow(0, offsets[i], parameters[i].numel())
            .view(parameters[i].sizes());
    view.copy_(parameters[i]);
    // The same tensors (the module's, the optimiser's state keys) on the
    // flat storage, as Module::to moves parameters.
    parameters[i].set_data(view);
  }
  flat_gradients_.assign(size, 0.0f);
  // FlatExemplarModel writes out MLP encoders' gradients only.
  if (fit == Ex2Fit::kFlat && !config.convolutional()) {
    absl::StatusOr<FlatExemplarModel> flat =
        FlatExemplarModel::Create(*model_, config_, parameters);
    // The model is always the layers FlatExemplarModel lays out.
    TORCH_CHECK(flat.ok(), "EX2's flat model: ", flat.status().ToString());
    flat_model_.emplace(*std::move(flat));
  }
  flat_adam_.emplace(std::move(parameters), std::move(offsets), size);
}

Ex2Bonus::~Ex2Bonus() = default;

std::vector<at::Tensor> Ex2Bonus::parameters() const {
  return model_->parameters();
}

at::Tensor Ex2Bonus::Inputs(const std::vector<Rollout>& rollouts) const {
  std::vector<at::Tensor> rows;
  for (const Rollout& rollout : rollouts) {
    const int64_t steps = rollout.rewards.size(0);
    at::Tensor states =
        NetworkInputs(spec_, rollout.observations.slice(0, 0, steps));
    if (!config_.use_actions) {
      rows.push_back(states);
      continue;
    }
    at::Tensor actions = rollout.actions;
    if (spec_.discrete) {
      // One one-hot per head, side by side: action_size values in all.
      std::vector<at::Tensor> hots;
      const std::vector<int64_t> heads = spec_.action_heads();
      for (size_t h = 0; h < heads.size(); ++h) {
        hots.push_back(at::one_hot(
            actions.select(1, static_cast<int64_t>(h)).to(at::kLong),
            heads[h]));
      }
      actions = at::cat(hots, 1).to(at::kFloat);
    } else {
      // What the environment executes, scaled to [-1, 1]: a policy sample
      // beyond the bounds (the actor stores it unclipped, for its
      // log-probability) must not look novel, or widening the policy
      // becomes the cheapest way to earn the bonus.
      const at::Tensor low = at::tensor(spec_.action_low, at::kDouble);
      const at::Tensor high = at::tensor(spec_.action_high, at::kDouble);
      actions =
          ((actions.to(at::kDouble) - (low + high) / 2) / ((high - low) / 2))
              .clamp(-1.0, 1.0);
    }
    rows.push_back(at::cat({states, actions.to(at::kFloat)}, 1));
  }
  return at::cat(rows).to(at::kFloat).contiguous();
}

at::Tensor Ex2Bonus::ByteRows(const std::vector<Rollout>& rollouts) const {
  std::vector<at::Tensor> rows;
  for (const Rollout& rollout : rollouts) {
    rows.push_back(rollout.observations.slice(0, 0, rollout.rewards.size(0)));
  }
  return at::cat(rows).reshape({-1, spec_.observation_size}).contiguous();
}

ExplorationStats Ex2Bonus::ShapeRewards(std::vector<Rollout>& rollouts) {
  ExplorationStats stats;
  const at::Tensor inputs = Inputs(rollouts);
  const int64_t m = inputs.size(0);
  if (pool_.total_added() >= config_.replay_min && pool_.size() > 0) {
    const int iterations =
        fitted_ ? config_.train_iterations : config_.first_train_iterations;
    double loss_sum = 0.0, accuracy_sum = 0.0;
    for (int i = 0; i < iterations; ++i) {
      const at::Tensor positives = inputs.index_select(
          0, at::randint(m, {config_.batch_size}, generator_,
                         at::TensorOptions(at::kLong)));
      const at::Tensor negatives =
          NetworkInputs(spec_, pool_.Sample(config_.batch_size, generator_));
      const auto [loss, accuracy] = FitStep(positives, negatives);
      loss_sum += loss;
      accuracy_sum += accuracy;
    }
    fitted_ = true;
    stats.fit_steps = iterations;
    stats.model_loss = loss_sum / iterations;
    stats.model_accuracy = accuracy_sum / iterations;
  }
  pending_ = pool_.dtype() == at::kByte ? ByteRows(rollouts) : inputs;
  // The reference checks the pool's size after adding the batch: one batch
  // earlier than the fit does.
  at::Tensor bonus = at::zeros({m}, at::kFloat);
  if (pool_.total_added() + m >= config_.replay_min) {
    bonus = NoveltyBonus(*model_, inputs);
  }
  const at::Tensor bonus_double = bonus.to(at::kDouble);
  stats.mean_bonus = bonus_double.mean().item<double>();
  stats.bonus_std = bonus_double.std(/*unbiased=*/false).item<double>();
  if (!std::isfinite(stats.mean_bonus)) {
    // The rewards stay as they are and the learner undoes the update.
    stats.fault = absl::StrCat(
        "non-finite exploration bonus (the EX2 model's mean loss this "
        "update: ",
        stats.model_loss, ")");
    return stats;
  }
  const at::Tensor shaped =
      (config_.bonus_coeff * (bonus_double - Median(bonus_double)))
          .to(at::kFloat);
  int64_t offset = 0;
  for (Rollout& rollout : rollouts) {
    const int64_t steps = rollout.rewards.size(0);
    rollout.rewards = rollout.rewards + shaped.slice(0, offset, offset + steps);
    offset += steps;
  }
  return stats;
}

std::pair<double, double> Ex2Bonus::FitStep(const at::Tensor& positives,
                                            const at::Tensor& negatives) {
  double loss = 0.0, accuracy = 0.0;
  if (flat_model_.has_value()) {
    const FlatExemplarLoss flat = flat_model_->LossAndGradient(
        flat_parameters_.data_ptr<float>(), positives, negatives,
        config_.kl_weight, generator_, flat_gradients_.data());
    loss = flat.loss;
    accuracy = flat.accuracy;
  } else {
    const ExemplarLoss autograd = ComputeExemplarLoss(
        *model_, positives, negatives, config_.kl_weight, generator_);
    AutogradStep(autograd.loss);
    loss = autograd.loss.item<double>();
    accuracy = autograd.accuracy;
    if (!flat_adam_.has_value()) return {loss, accuracy};
  }
  // EX2 does not clip its gradients, so their norm is never needed.
  AverageFlatGradient(flat_gradients_.data(),
                      static_cast<int64_t>(flat_gradients_.size()), *replicas_);
  flat_adam_->Step(*optimizer_, flat_parameters_.data_ptr<float>(),
                   flat_gradients_.data());
  return {loss, accuracy};
}

void Ex2Bonus::AutogradStep(const at::Tensor& loss) {
  const std::vector<at::Tensor> parameters = model_->parameters();
  if (!flat_adam_.has_value()) {
    constexpr double kNoClipping = std::numeric_limits<double>::infinity();
    GradientStep(*optimizer_, parameters, loss, kNoClipping, *replicas_);
    return;
  }
  // Undefined gradients are taken over by backward, not accumulated into.
  for (const at::Tensor& p : parameters) p.mutable_grad().reset();
  loss.backward();
  int64_t offset = 0;
  for (const at::Tensor& p : parameters) {
    const at::Tensor& grad = p.grad();
    float* target = flat_gradients_.data() + offset;
    if (grad.defined()) {
      const at::Tensor values = grad.contiguous();
      std::memcpy(target, values.data_ptr<float>(),
                  sizeof(float) * values.numel());
    } else {
      std::fill_n(target, p.numel(), 0.0f);
    }
    offset += p.numel();
  }
}

void Ex2Bonus::Commit() {
  if (!pending_.defined()) return;
  pool_.Add(pending_);
  pending_ = at::Tensor();
}

void Ex2Bonus::SaveModelState(torch::serialize::OutputArchive& archive,
                              const std::string& prefix) const {
  WriteModule(archive, prefix + ".model", *model_);
  if (flat_adam_.has_value()) flat_adam_->StoreInto(*optimizer_);
  SaveOptimizer(*optimizer_, prefix + ".optimizer", archive);
  archive.write(prefix + ".generator", generator_.get_state());
  archive.write(prefix + ".fitted",
                at::tensor({static_cast<int64_t>(fitted_)}));
}

absl::Status Ex2Bonus::LoadModelState(torch::serialize::InputArchive& archive,
                                      const std::string& prefix) {
  at::Tensor generator_state, fitted;
  for (absl::Status status :
       {ReadTensor(archive, prefix + ".generator", generator_state),
        ReadTensor(archive, prefix + ".fitted", fitted)}) {
    if (!status.ok()) return status;
  }
  if (generator_state.scalar_type() != at::kByte ||
      generator_state.sizes() != generator_.get_state().sizes() ||
      fitted.scalar_type() != at::kLong || fitted.numel() != 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("checkpoint entries '", prefix, ".generator' or '", prefix,
                     ".fitted' are malformed"));
  }
  // A generator state of the right size can still be invalid (LibTorch
  // checks its fields): tried on a scratch generator first.
  at::Generator restored = at::make_generator<at::CPUGeneratorImpl>(0);
  if (absl::Status status =
          CatchTorchErrors(absl::StrCat("checkpoint entry '", prefix,
                                        ".generator' is not a generator state"),
                           [&] { restored.set_state(generator_state); });
      !status.ok()) {
    return status;
  }
  // Checked before anything changes: the module's entries, then the
  // optimiser's (which LoadOptimizer checks against the model).
  if (absl::Status status = ReadModule(archive, prefix + ".model", *model_);
      !status.ok()) {
    return status;
  }
  if (absl::Status status =
          LoadOptimizer(*optimizer_, prefix + ".optimizer", archive);
      !status.ok()) {
    return status;
  }
  if (flat_adam_.has_value()) {
    if (absl::Status status = flat_adam_->LoadFrom(*optimizer_); !status.ok()) {
      return status;
    }
  }
  generator_ = restored;
  fitted_ = fitted.item<int64_t>() != 0;
  pending_ = at::Tensor();
  return absl::OkStatus();
}

void Ex2Bonus::Save(torch::serialize::OutputArchive& archive,
                    const std::string& prefix) const {
  SaveModelState(archive, prefix);
  pool_.Save(archive, prefix + ".pool");
}

absl::Status Ex2Bonus::Load(torch::serialize::InputArchive& archive,
                            const std::string& prefix) {
  if (absl::Status status = pool_.Load(archive, prefix + ".pool");
      !status.ok()) {
    return status;
  }
  return LoadModelState(archive, prefix);
}

}  // namespace vantage
