#include "bench/learner_bench.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <benchmark/benchmark.h>
#include <torch/nn/modules/activation.h>
#include <torch/nn/modules/container/sequential.h>
#include <torch/nn/modules/linear.h>
#include <torch/optim/adam.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "bench/fastest.h"
#include "learner/algorithms/ppo/ppo_updater.h"
#include "learner/update_guard.h"

namespace vantage {
namespace {

// HalfCheetah's sizes and the baselines' PPO settings.
constexpr int64_t kObservations = 17;
constexpr int64_t kActions = 6;
constexpr int64_t kBatch = 2048;
constexpr int kMinibatches = 32;
constexpr int kEpochs = 10;
constexpr int kRepetitions = 10;

EnvSpec HalfCheetahSpec() {
  EnvSpec spec;
  spec.name = "HalfCheetah";
  spec.observation_size = kObservations;
  spec.action_size = kActions;
  spec.action_low.assign(kActions, -1.0);
  spec.action_high.assign(kActions, 1.0);
  return spec;
}

torch::nn::Sequential BareMlp(int64_t outputs) {
  return torch::nn::Sequential(torch::nn::Linear(kObservations, 64),
                               torch::nn::Tanh(), torch::nn::Linear(64, 64),
                               torch::nn::Tanh(),
                               torch::nn::Linear(64, outputs));
}

// The least a PPO update must do: shuffled minibatches, both networks
// forward, the Gaussian log-probability, the clipped surrogate and the
// value loss, backward, one Adam step.
class BarePpo {
 public:
  BarePpo()
      : policy_(BareMlp(kActions)),
        value_(BareMlp(1)),
        log_std_(at::zeros({kActions}).set_requires_grad(true)) {
    std::vector<at::Tensor> parameters = policy_->parameters();
    for (const at::Tensor& p : value_->parameters()) parameters.push_back(p);
    parameters.push_back(log_std_);
    optimizer_ = std::make_unique<torch::optim::Adam>(
        parameters, torch::optim::AdamOptions(3e-4).eps(1e-5));
  }

  void Update(const UpdateBatch& batch) {
    const int64_t minibatch = kBatch / kMinibatches;
    for (int epoch = 0; epoch < kEpochs; ++epoch) {
      const at::Tensor permutation = at::randperm(kBatch, at::kLong);
      for (int64_t begin = 0; begin < kBatch; begin += minibatch) {
        const at::Tensor index = permutation.slice(0, begin, begin + minibatch);
        const at::Tensor obs = batch.observations.index_select(0, index);
        const at::Tensor actions = batch.actions.index_select(0, index);
        const at::Tensor mean = policy_->forward(obs);
        const at::Tensor z = (actions - mean) * at::exp(-log_std_);
        const at::Tensor log_prob = (-0.5 * z * z - log_std_).sum(-1) -
                                    0.5 * kActions * std::log(2 * M_PI);
        const at::Tensor ratio = at::exp(
            log_prob - batch.behaviour_log_probs.index_select(0, index));
        const at::Tensor adv = batch.advantages.index_select(0, index);
        const at::Tensor policy_loss =
            -at::min(ratio * adv, ratio.clamp(0.8, 1.2) * adv).mean();
        const at::Tensor error = value_->forward(obs).squeeze(-1) -
                                 batch.returns.index_select(0, index);
        const at::Tensor loss =
            policy_loss + 0.5 * 0.5 * (error * error).mean();
        optimizer_->zero_grad();
        loss.backward();
        optimizer_->step();
      }
    }
  }

 private:
  torch::nn::Sequential policy_;
  torch::nn::Sequential value_;
  at::Tensor log_std_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

UpdateBatch SyntheticBatch() {
  UpdateBatch batch;
  batch.horizon = kBatch;
  batch.streams = 1;
  batch.observations = at::randn({kBatch, kObservations});
  batch.actions = at::randn({kBatch, kActions}).clamp(-1, 1);
  batch.behaviour_log_probs = at::randn({kBatch}) - 6;
  batch.advantages = at::randn({kBatch});
  batch.returns = at::randn({kBatch});
  return batch;
}

}  // namespace

int RunLearnerBenchmark() {
  at::set_num_threads(1);
  at::manual_seed(0);
  const UpdateBatch batch = SyntheticBatch();

  NetworkConfig network;  // 64x64
  PolicyNetwork policy(HalfCheetahSpec(), network);
  ValueNetwork value(kObservations, network);
  PpoConfig config;
  config.minibatches = kMinibatches;
  config.epochs = kEpochs;
  PpoUpdater ppo(policy, value, config);
  std::mt19937_64 rng(0);
  // A learning rate that keeps the synthetic problem's updates tiny, so
  // every repetition does the same work on similar parameters.
  const double progress = 0.999;
  benchmark::RegisterBenchmark("ppo_update", [&](benchmark::State& state) {
    for (auto _ : state) {
      benchmark::DoNotOptimize(ppo.Update(batch, progress, rng));
    }
  })->Apply([](auto* b) { UseFastestOfSingleRuns(b, kRepetitions); });

  // The same update inside the learner's rollback guard (snapshot before,
  // finiteness checks after), which every learner update pays for.
  benchmark::RegisterBenchmark("guarded_ppo_update", [&](benchmark::State&
                                                             state) {
    for (auto _ : state) {
      UpdateGuard guard(*policy, *value, ppo, /*reward_scaler=*/nullptr);
      const AlgorithmStats stats = ppo.Update(batch, progress, rng);
      benchmark::DoNotOptimize(
          guard.Fault(stats, std::numeric_limits<double>::infinity()));
    }
  })->Apply([](auto* b) { UseFastestOfSingleRuns(b, kRepetitions); });

  BarePpo bare;
  benchmark::RegisterBenchmark("bare_update", [&](benchmark::State& state) {
    for (auto _ : state) bare.Update(batch);
  })->Apply([](auto* b) { UseFastestOfSingleRuns(b, kRepetitions); });

  std::printf(
      "learner: PPO update of %ld samples x %d epochs in %d minibatches, "
      "obs %ld, act %ld, 64x64 tanh networks, one thread\n",
      static_cast<long>(kBatch), kEpochs, kMinibatches,
      static_cast<long>(kObservations), static_cast<long>(kActions));
  FastestCollector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  const double samples = static_cast<double>(kBatch) * kEpochs;
  const double ppo_rate = samples / collector.Seconds("ppo_update");
  const double bare_rate = samples / collector.Seconds("bare_update");
  const double guarded_rate = samples / collector.Seconds("guarded_ppo_update");
  std::printf(
      "RESULT learner ppo_samples_per_s=%.0f bare_samples_per_s=%.0f "
      "ratio=%.3f guarded_samples_per_s=%.0f guard_ratio=%.3f\n",
      ppo_rate, bare_rate, ppo_rate / bare_rate, guarded_rate,
      guarded_rate / ppo_rate);
  return 0;
}

}  // namespace vantage
