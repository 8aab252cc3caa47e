#include "bench/recurrent_learner_bench.h"

#include <ATen/ATen.h>
#include <benchmark/benchmark.h>
#include <torch/nn/modules/activation.h>
#include <torch/nn/modules/container/sequential.h>
#include <torch/nn/modules/linear.h>
#include <torch/nn/modules/rnn.h>
#include <torch/optim/adam.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "absl/strings/str_cat.h"
#include "bench/bare_ppo.h"
#include "bench/fastest.h"
#include "common/nn/compute_threads.h"
#include "common/nn/networks.h"
#include "learner/algorithms/chunk_minibatches.h"
#include "learner/algorithms/ppo/ppo_updater.h"

namespace vantage {
namespace {

// HalfCheetah's sizes, as BarePpoShape's defaults (BenchSpec).
constexpr int64_t kObservations = 17;
constexpr int64_t kActions = 6;
constexpr int64_t kStreams = 16;
constexpr int64_t kHorizon = 128;
constexpr int64_t kSeqLen = 16;
constexpr int kMinibatches = 32;
constexpr int kEpochs = 10;
constexpr int kRepetitions = 5;

// Random rows, no episode starts, small random chunk states.
UpdateBatch RecurrentBatch(int64_t state_size) {
  const int64_t samples = kStreams * kHorizon;
  UpdateBatch batch;
  batch.horizon = kHorizon;
  batch.streams = kStreams;
  batch.observations = at::randn({samples, kObservations});
  batch.actions = at::randn({samples, kActions}).clamp(-1, 1);
  batch.behaviour_log_probs = at::randn({samples}) - 6;
  batch.advantages = at::randn({samples});
  batch.returns = at::randn({samples});
  batch.seq_len = kSeqLen;
  batch.starts = at::zeros({samples}, at::kBool);
  batch.chunk_states =
      at::randn({kHorizon / kSeqLen * kStreams, state_size}) * 0.1;
  return batch;
}

// The least a recurrent PPO update must do, against LibTorch's sequence
// modules: shuffled minibatches of whole chunks, the encoder, the core over
// each chunk from its start state, both heads, the clipped surrogate and
// the value loss, backward, one Adam step.
class BareRecurrentPpo {
 public:
  explicit BareRecurrentPpo(const NetworkConfig& network)
      : lstm_(network.core == Core::kLstm),
        hidden_(network.core_size),
        log_std_(at::zeros({kActions}).set_requires_grad(true)) {
    encoder_->push_back(torch::nn::Linear(kObservations, 64));
    encoder_->push_back(torch::nn::Tanh());
    encoder_->push_back(torch::nn::Linear(64, 64));
    encoder_->push_back(torch::nn::Tanh());
    if (lstm_) {
      lstm_core_ = torch::nn::LSTM(torch::nn::LSTMOptions(64, hidden_));
    } else {
      gru_core_ = torch::nn::GRU(torch::nn::GRUOptions(64, hidden_));
    }
    std::vector<at::Tensor> parameters = encoder_->parameters();
    for (const at::Tensor& p :
         lstm_ ? lstm_core_->parameters() : gru_core_->parameters()) {
      parameters.push_back(p);
    }
    for (const at::Tensor& p : policy_head_->parameters()) {
      parameters.push_back(p);
    }
    for (const at::Tensor& p : value_head_->parameters()) {
      parameters.push_back(p);
    }
    parameters.push_back(log_std_);
    optimizer_ = std::make_unique<torch::optim::Adam>(
        parameters, torch::optim::AdamOptions(3e-4).eps(1e-5));
  }

  void Update(const UpdateBatch& batch, std::mt19937_64& rng) {
    for (int epoch = 0; epoch < kEpochs; ++epoch) {
      for (const ChunkMinibatch& m :
           ShuffledChunkMinibatches(batch, kMinibatches, rng)) {
        Step(batch, m);
      }
    }
  }

 private:
  at::Tensor Core(const at::Tensor& x, const at::Tensor& state) {
    if (!lstm_) {
      return std::get<0>(gru_core_->forward(x, state.unsqueeze(0)));
    }
    return std::get<0>(lstm_core_->forward(
        x, std::make_tuple(state.narrow(1, 0, hidden_).unsqueeze(0),
                           state.narrow(1, hidden_, hidden_).unsqueeze(0))));
  }

  void Step(const UpdateBatch& batch, const ChunkMinibatch& m) {
    const int64_t chunks = m.chunks.size(0);
    const at::Tensor obs = batch.observations.index_select(0, m.rows);
    const at::Tensor features =
        Core(encoder_->forward(obs).reshape({kSeqLen, chunks, 64}),
             batch.chunk_states.index_select(0, m.chunks))
            .reshape({kSeqLen * chunks, hidden_});
    const at::Tensor mean = policy_head_->forward(features);
    const at::Tensor z =
        (batch.actions.index_select(0, m.rows) - mean) * at::exp(-log_std_);
    const at::Tensor log_prob =
        (-0.5 * z * z - log_std_).sum(-1) - 0.5 * kActions * std::log(2 * M_PI);
    const at::Tensor ratio =
        at::exp(log_prob - batch.behaviour_log_probs.index_select(0, m.rows));
    const at::Tensor adv = batch.advantages.index_select(0, m.rows);
    const at::Tensor policy_loss =
        -at::min(ratio * adv, ratio.clamp(0.8, 1.2) * adv).mean();
    const at::Tensor error = value_head_->forward(features).squeeze(-1) -
                             batch.returns.index_select(0, m.rows);
    const at::Tensor loss = policy_loss + 0.5 * 0.5 * (error * error).mean();
    optimizer_->zero_grad();
    loss.backward();
    optimizer_->step();
  }

  const bool lstm_;
  const int64_t hidden_;
  torch::nn::Sequential encoder_;
  torch::nn::LSTM lstm_core_{nullptr};
  torch::nn::GRU gru_core_{nullptr};
  torch::nn::Linear policy_head_{torch::nn::Linear(hidden_, kActions)};
  torch::nn::Linear value_head_{torch::nn::Linear(hidden_, 1)};
  at::Tensor log_std_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

}  // namespace

int RunRecurrentLearnerBenchmark(const NetworkConfig& core) {
  SetComputeThreads(1);
  at::manual_seed(0);
  NetworkConfig network = core;
  network.hidden = {64, 64};
  network.seq_len = kSeqLen;
  const UpdateBatch batch = RecurrentBatch(network.core_state_size());
  const EnvSpec spec = BenchSpec(BarePpoShape());
  PolicyNetwork policy(spec, network);
  ValueNetwork value = MakeValueNetwork(spec, network, *policy);
  PpoConfig config;
  config.minibatches = kMinibatches;
  config.epochs = kEpochs;
  PpoUpdater ppo(policy, value, config);
  BareRecurrentPpo bare(network);
  std::mt19937_64 rng(0);
  // A learning rate that keeps the synthetic problem's updates tiny.
  const double progress = 0.999;
  benchmark::RegisterBenchmark("recurrent_ppo_update", [&](benchmark::State&
                                                               state) {
    for (auto _ : state) {
      benchmark::DoNotOptimize(ppo.Update(batch, progress, rng));
    }
  })->Apply([](auto* b) { UseFastestOfSingleRuns(b, kRepetitions); });
  benchmark::RegisterBenchmark("bare_recurrent_update",
                               [&](benchmark::State& state) {
                                 for (auto _ : state) bare.Update(batch, rng);
                               })
      ->Apply([](auto* b) { UseFastestOfSingleRuns(b, kRepetitions); });
  const std::string name =
      absl::StrCat(CoreName(network.core), ":", network.core_size);
  std::printf(
      "learner: recurrent PPO update of %ld streams x %ld steps in chunks of "
      "%ld, %d minibatches, %d epochs, obs %ld, act %ld, 64x64 encoder, core "
      "%s, one thread; the bare loop uses torch::nn::%s\n",
      static_cast<long>(kStreams), static_cast<long>(kHorizon),
      static_cast<long>(kSeqLen), kMinibatches, kEpochs,
      static_cast<long>(kObservations), static_cast<long>(kActions),
      name.c_str(), network.core == Core::kLstm ? "LSTM" : "GRU");
  FastestCollector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  const double samples = static_cast<double>(kStreams * kHorizon) * kEpochs;
  const double ppo_rate = samples / collector.Seconds("recurrent_ppo_update");
  const double bare_rate = samples / collector.Seconds("bare_recurrent_update");
  std::printf(
      "RESULT learner_recurrent core=%s ppo_samples_per_s=%.0f "
      "bare_samples_per_s=%.0f ratio=%.3f\n",
      name.c_str(), ppo_rate, bare_rate, ppo_rate / bare_rate);
  return 0;
}

}  // namespace vantage
