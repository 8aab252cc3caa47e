#include "bench/learner_bench.h"

#include <ATen/ATen.h>
#include <ATen/CPUGeneratorImpl.h>
#include <benchmark/benchmark.h>
#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <random>
#include <thread>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "bench/bare_ppo.h"
#include "bench/blas_library.h"
#include "bench/fastest.h"
#include "common/net/loopback_port.h"
#include "common/nn/compute_threads.h"
#include "common/util/self_process.h"
#include "learner/algorithms/a2c/a2c_updater.h"
#include "learner/algorithms/flat_adam.h"
#include "learner/algorithms/ppo/ppo_updater.h"
#include "learner/exploration/ex2_bonus.h"
#include "learner/parallel/gloo_replica_group.h"
#include "learner/update/update_guard.h"

namespace vantage {
namespace {

// HalfCheetah's sizes and the baselines' PPO settings.
constexpr int64_t kObservations = 17;
constexpr int64_t kActions = 6;
constexpr int64_t kBatch = 2048;
constexpr int kMinibatches = 32;
constexpr int kEpochs = 10;
constexpr int kRepetitions = 10;

BarePpoShape BenchShape() {
  BarePpoShape shape;
  shape.observations = kObservations;
  shape.actions = kActions;
  shape.minibatches = kMinibatches;
  shape.epochs = kEpochs;
  return shape;
}

EnvSpec HalfCheetahSpec() { return BenchSpec(BenchShape()); }

UpdateBatch SyntheticBatch() { return SyntheticBatch(BenchShape(), kBatch); }

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

struct DataParallelFigures {
  int64_t gradient_floats = 0;
  double allreduce_seconds = 0.0;  // one gradient all-reduce, mean
  double update_seconds = 0.0;     // the whole update, fastest
};

PpoConfig BenchPpoConfig(int minibatches = kMinibatches, int epochs = kEpochs) {
  PpoConfig config;
  config.minibatches = minibatches;
  config.epochs = epochs;
  return config;
}

// The scaling sweep's batch: 8192 samples (4096 per replica), 4 epochs.
constexpr int64_t kScalingBatch = 8192;
constexpr int kScalingEpochs = 4;

// Replica `rank` of two learner processes joined over loopback Gloo as in
// `vantage train --learners=2`, each updating on its half of `batch` with
// the gradients averaged every minibatch (so the global minibatch is the
// single learner's).
DataParallelFigures RunReplica(int rank, const std::string& rendezvous,
                               const UpdateBatch& batch,
                               const PpoConfig& config = BenchPpoConfig()) {
  ReplicaGroupConfig group_config;
  group_config.rank = rank;
  group_config.world_size = 2;
  group_config.rendezvous = rendezvous;
  group_config.timeout = absl::Seconds(120);
  std::shared_ptr<ReplicaGroup> group = JoinReplicaGroup(group_config).value();
  NetworkConfig network;
  PolicyNetwork policy(HalfCheetahSpec(), network);
  ValueNetwork value(kObservations, network);
  std::vector<at::Tensor> parameters = policy->parameters();
  for (const at::Tensor& p : value->parameters()) parameters.push_back(p);
  {
    at::NoGradGuard no_grad;
    group->Broadcast(parameters, /*root=*/0);
  }
  DataParallelFigures figures;
  for (const at::Tensor& p : parameters) figures.gradient_floats += p.numel();
  std::vector<at::Tensor> gradient = {at::zeros({figures.gradient_floats})};
  constexpr int kWarmup = 50;
  constexpr int kAllReduces = 2000;
  for (int i = 0; i < kWarmup; ++i) group->AllReduceSum(gradient);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < kAllReduces; ++i) group->AllReduceSum(gradient);
  figures.allreduce_seconds = SecondsSince(start) / kAllReduces;

  const int64_t half = batch.observations.size(0) / 2;
  UpdateBatch own;
  own.horizon = half;
  own.streams = 1;
  auto rows = [&](const at::Tensor& t) {
    return t.slice(0, rank * half, (rank + 1) * half).contiguous();
  };
  own.observations = rows(batch.observations);
  own.actions = rows(batch.actions);
  own.behaviour_log_probs = rows(batch.behaviour_log_probs);
  own.advantages = rows(batch.advantages);
  own.returns = rows(batch.returns);
  PpoUpdater ppo(policy, value, config, group);
  std::mt19937_64 rng(rank);
  figures.update_seconds = std::numeric_limits<double>::infinity();
  // The first is a warm-up; both replicas run in lockstep.
  for (int i = 0; i <= kRepetitions; ++i) {
    const auto update_start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(ppo.Update(own, 0.999, rng));
    if (i > 0) {
      figures.update_seconds =
          std::min(figures.update_seconds, SecondsSince(update_start));
    }
  }
  return figures;
}

// The second replica in a child process: the replicas of a real run are
// processes, and two threads of one process measured several times
// slower collectives than two processes.
// `minibatch` > 0: the scaling sweep's shape with that (global) minibatch
// size; 0: the benchmark's own.
absl::StatusOr<DataParallelFigures> MeasureTwoReplicas(const UpdateBatch& batch,
                                                       int64_t minibatch = 0) {
  absl::StatusOr<int> port = FreeLoopbackPort();
  if (!port.ok()) return port.status();
  const std::string rendezvous = absl::StrCat("127.0.0.1:", *port);
  absl::StatusOr<pid_t> child =
      SpawnSelf({"bench", "learner", "--bench_replica_of=" + rendezvous,
                 absl::StrCat("--bench_replica_minibatch=", minibatch)});
  if (!child.ok()) return child.status();
  const DataParallelFigures figures =
      minibatch > 0 ? RunReplica(0, rendezvous, batch,
                                 BenchPpoConfig(kScalingBatch / minibatch,
                                                kScalingEpochs))
                    : RunReplica(0, rendezvous, batch);
  int status = 0;
  waitpid(*child, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    return absl::InternalError("the second learner replica failed");
  }
  return figures;
}

}  // namespace

int RunLearnerBenchmarkReplica(const std::string& rendezvous,
                               int64_t minibatch) {
  SetComputeThreads(1);
  at::manual_seed(0);
  if (minibatch > 0) {
    RunReplica(1, rendezvous, SyntheticBatch(BenchShape(), kScalingBatch),
               BenchPpoConfig(kScalingBatch / minibatch, kScalingEpochs));
  } else {
    RunReplica(1, rendezvous, SyntheticBatch());
  }
  return 0;
}

namespace {

// Samples/s of one PPO update of `batch` (fastest of three after a
// warm-up) with `threads` intra-op threads.
double OneLearnerRate(const UpdateBatch& batch, const PpoConfig& config,
                      int threads) {
  SetComputeThreads(threads);
  NetworkConfig network;
  PolicyNetwork policy(HalfCheetahSpec(), network);
  ValueNetwork value(kObservations, network);
  PpoUpdater ppo(policy, value, config);
  std::mt19937_64 rng(0);
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= 3; ++i) {
    const auto start = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(ppo.Update(batch, 0.999, rng));
    if (i > 0) best = std::min(best, SecondsSince(start));
  }
  SetComputeThreads(1);
  return static_cast<double>(batch.observations.size(0)) * config.epochs / best;
}

}  // namespace

int RunLearnerScalingBenchmark(const std::vector<int64_t>& minibatches,
                               const std::vector<int>& thread_counts) {
  SetComputeThreads(1);
  at::manual_seed(0);
  const UpdateBatch batch = SyntheticBatch(BenchShape(), kScalingBatch);
  std::printf(
      "learner scaling: PPO updates of %ld samples x %d epochs, obs %ld, act "
      "%ld, 64x64 tanh networks, against the minibatch size; one learner at "
      "each thread count, and two replicas (processes over loopback Gloo, "
      "one thread each, half the batch and of each minibatch each)\n",
      static_cast<long>(kScalingBatch), kScalingEpochs,
      static_cast<long>(kObservations), static_cast<long>(kActions));
  std::string header = "  minibatch";
  for (int threads : thread_counts) {
    absl::StrAppend(&header, absl::StrFormat("  %2d thread(s)", threads));
  }
  std::printf("%s  two replicas  (x one, 1 thread)  all-reduce share\n",
              header.c_str());
  std::string result = "RESULT learner_scaling";
  for (int64_t minibatch : minibatches) {
    if (minibatch < 2 || kScalingBatch % minibatch != 0) {
      std::fprintf(
          stderr, "bench learner_scaling: minibatch %ld must divide %ld\n",
          static_cast<long>(minibatch), static_cast<long>(kScalingBatch));
      return 2;
    }
    const PpoConfig config =
        BenchPpoConfig(kScalingBatch / minibatch, kScalingEpochs);
    std::string row = absl::StrFormat("  %9ld", static_cast<long>(minibatch));
    double one = 0;
    for (int threads : thread_counts) {
      const double rate = OneLearnerRate(batch, config, threads);
      if (threads == thread_counts.front()) one = rate;
      absl::StrAppend(&row, absl::StrFormat("  %12.0f", rate));
      absl::StrAppend(&result, " mb", minibatch, "_t", threads, "=",
                      absl::StrFormat("%.0f", rate));
    }
    absl::StatusOr<DataParallelFigures> two =
        MeasureTwoReplicas(batch, minibatch);
    if (!two.ok()) {
      std::fprintf(stderr, "bench learner_scaling: %s\n",
                   std::string(two.status().message()).c_str());
      return 1;
    }
    const double two_rate = static_cast<double>(kScalingBatch) *
                            kScalingEpochs / two->update_seconds;
    const double share = two->allreduce_seconds * (kScalingBatch / minibatch) *
                         kScalingEpochs / two->update_seconds;
    std::printf("%s  %12.0f  %17.2f  %16.0f%%\n", row.c_str(), two_rate,
                two_rate / one, 100 * share);
    absl::StrAppend(
        &result, " mb", minibatch,
        "_two_replicas=", absl::StrFormat("%.0f", two_rate), " mb", minibatch,
        "_two_replicas_speedup=", absl::StrFormat("%.2f", two_rate / one));
  }
  std::printf("%s\n", result.c_str());
  return 0;
}

// Adam over about as many floats as EX2's model on the first-person maze's
// frames holds (348,289: two MLP encoders of 3 x 42 x 42 pixels into 32
// units with their latent heads, and the discriminator), where the
// optimiser's pass over memory is a visible share of the fit: FlatAdam's
// one pass against torch::optim::Adam's step on the same tensors.
class FrameSizedAdam {
 public:
  FrameSizedAdam() {
    // A generator of its own: the global one seeds the benchmarks after.
    at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(3);
    for (std::array<int64_t, 2> shape :
         {std::array<int64_t, 2>{32, 5292}, {32, 5292}, {32, 32}, {32, 32}}) {
      for (int64_t rows : {shape[0] * shape[1], shape[0]}) {
        parameters_.push_back(at::randn({rows}, generator) * 0.01);
        parameters_.back().mutable_grad() = at::randn({rows}, generator) * 1e-3;
        offsets_.push_back(size_);
        size_ += rows;
      }
    }
    flat_parameters_ = at::cat(parameters_).contiguous();
    flat_gradients_ = at::cat(GradientsOf(parameters_)).contiguous();
    torch_ = std::make_unique<torch::optim::Adam>(
        parameters_, torch::optim::AdamOptions(1e-4));
    flat_ = std::make_unique<FlatAdam>(parameters_, offsets_, size_);
  }

  void Register() {
    benchmark::RegisterBenchmark("adam_flat_step", [this](benchmark::State&
                                                              state) {
      for (auto _ : state) {
        flat_->Step(*torch_, flat_parameters_.data_ptr<float>(),
                    flat_gradients_.data_ptr<float>());
      }
    })->Apply([](auto* b) { UseFastestOfSingleRuns(b, kRepetitions); });
    benchmark::RegisterBenchmark("adam_torch_step",
                                 [this](benchmark::State& state) {
                                   for (auto _ : state) torch_->step();
                                 })
        ->Apply([](auto* b) { UseFastestOfSingleRuns(b, kRepetitions); });
  }

  int64_t size() const { return size_; }

 private:
  static std::vector<at::Tensor> GradientsOf(
      const std::vector<at::Tensor>& ps) {
    std::vector<at::Tensor> gradients;
    for (const at::Tensor& p : ps) gradients.push_back(p.grad());
    return gradients;
  }

  std::vector<at::Tensor> parameters_;
  std::vector<int64_t> offsets_;
  int64_t size_ = 0;
  at::Tensor flat_parameters_;
  at::Tensor flat_gradients_;
  std::unique_ptr<torch::optim::Adam> torch_;
  std::unique_ptr<FlatAdam> flat_;
};

int RunLearnerBenchmark() {
  SetComputeThreads(1);
  at::manual_seed(0);
  const UpdateBatch batch = SyntheticBatch();

  NetworkConfig network;  // 64x64
  PolicyNetwork policy(HalfCheetahSpec(), network);
  ValueNetwork value(kObservations, network);
  PpoUpdater ppo(policy, value, BenchPpoConfig());
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

  // A2C's update (defaults: 4 consecutive minibatches of 5 steps) of 16
  // envs, on the flat path and on autograd: the same steps, which
  // a2c_updater_test compares.
  constexpr int64_t kA2cStreams = 16;
  const A2cConfig a2c_config;
  UpdateBatch a2c_batch =
      SyntheticBatch(BenchShape(), a2c_config.horizon() * kA2cStreams);
  a2c_batch.horizon = a2c_config.horizon();
  a2c_batch.streams = kA2cStreams;
  A2cUpdater a2c_flat(policy, value, a2c_config);
  A2cUpdater a2c_autograd(policy, value, a2c_config, SoloReplicaGroup(),
                          /*autograd_only=*/true);
  constexpr int kA2cUpdates = 100;  // per repetition: each is ~0.1 ms
  for (auto [name, updater] : {std::pair{"a2c_flat_update", &a2c_flat},
                               {"a2c_autograd_update", &a2c_autograd}}) {
    benchmark::RegisterBenchmark(name, [&, updater = updater](
                                           benchmark::State& state) {
      for (auto _ : state) {
        for (int i = 0; i < kA2cUpdates; ++i) {
          benchmark::DoNotOptimize(updater->Update(a2c_batch, progress, rng));
        }
      }
    })->Apply([](auto* b) { UseFastestOfSingleRuns(b, kRepetitions); });
  }

  // EX2's model fit (its reference code's settings but for fewer
  // iterations) on HalfCheetah's states and actions: the flat model and
  // Adam (the default), autograd's gradients with the flat Adam, and
  // autograd with torch's Adam.
  Ex2Config ex2_config;
  ex2_config.replay_min = 1;
  ex2_config.first_train_iterations = 1;
  constexpr int kEx2Iterations = 200;
  ex2_config.train_iterations = kEx2Iterations;
  Rollout ex2_rollout;
  ex2_rollout.observations = at::randn({1001, kObservations});
  ex2_rollout.actions = at::randn({1000, kActions});
  ex2_rollout.rewards = at::zeros({1000});
  Ex2Bonus ex2_flat(ex2_config, HalfCheetahSpec(), 1, SoloReplicaGroup());
  Ex2Bonus ex2_autograd(ex2_config, HalfCheetahSpec(), 1, SoloReplicaGroup(),
                        Ex2Fit::kAutograd);
  Ex2Bonus ex2_torch(ex2_config, HalfCheetahSpec(), 1, SoloReplicaGroup(),
                     Ex2Fit::kTorch);
  const std::pair<const char*, Ex2Bonus*> ex2_fits[] = {
      {"ex2_flat_fit", &ex2_flat},
      {"ex2_autograd_fit", &ex2_autograd},
      {"ex2_torch_fit", &ex2_torch}};
  for (auto [name, ex2] : ex2_fits) {
    // The pool's first rows, then the first fit (of one iteration): the
    // timed ones are all of kEx2Iterations.
    for (int i = 0; i < 2; ++i) {
      std::vector<Rollout> rollouts = {ex2_rollout};
      ex2->ShapeRewards(rollouts);
      ex2->Commit();
    }
    benchmark::RegisterBenchmark(name, [&, ex2 = ex2](benchmark::State& state) {
      for (auto _ : state) {
        std::vector<Rollout> rollouts = {ex2_rollout};
        benchmark::DoNotOptimize(ex2->ShapeRewards(rollouts));
      }
    })->Apply([](auto* b) { UseFastestOfSingleRuns(b, kRepetitions); });
  }

  FrameSizedAdam frame_adam;
  frame_adam.Register();

  BarePpo bare(BenchShape());
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
  const double a2c_samples =
      static_cast<double>(a2c_batch.observations.size(0)) * kA2cUpdates;
  const double a2c_flat_rate =
      a2c_samples / collector.Seconds("a2c_flat_update");
  const double a2c_autograd_rate =
      a2c_samples / collector.Seconds("a2c_autograd_update");
  const double ex2_flat_rate =
      kEx2Iterations / collector.Seconds("ex2_flat_fit");
  const double ex2_autograd_rate =
      kEx2Iterations / collector.Seconds("ex2_autograd_fit");
  const double ex2_torch_rate =
      kEx2Iterations / collector.Seconds("ex2_torch_fit");
  const double adam_flat_rate = 1.0 / collector.Seconds("adam_flat_step");
  const double adam_torch_rate = 1.0 / collector.Seconds("adam_torch_step");
  absl::StatusOr<DataParallelFigures> measured = MeasureTwoReplicas(batch);
  if (!measured.ok()) {
    std::fprintf(stderr, "bench learner: %s\n",
                 std::string(measured.status().message()).c_str());
    return 1;
  }
  const DataParallelFigures& two = *measured;
  const double steps = static_cast<double>(kMinibatches) * kEpochs;
  const double dp_rate = samples / two.update_seconds;
  const double allreduce_share =
      two.allreduce_seconds * steps / two.update_seconds;
  std::printf(
      "learner: two replicas (processes joined over loopback Gloo, half the "
      "batch each): %.0f samples/s, %.2fx one learner; each all-reduce of "
      "%ld gradient floats %.1f us, %.0f%% of their update\n",
      dp_rate, dp_rate / ppo_rate, static_cast<long>(two.gradient_floats),
      two.allreduce_seconds * 1e6, 100 * allreduce_share);
  const BlasLibrary blas = LoadedBlasLibrary();
  std::printf("learner: BLAS %s (%s%s%s)\n",
              blas.path.empty() ? "?" : blas.path.c_str(), blas.kind.c_str(),
              blas.details.empty() ? "" : ": ", blas.details.c_str());
  std::printf(
      "RESULT learner ppo_samples_per_s=%.0f bare_samples_per_s=%.0f "
      "ratio=%.3f guarded_samples_per_s=%.0f guard_ratio=%.3f "
      "two_replicas_samples_per_s=%.0f two_replicas_speedup=%.2f "
      "allreduce_us=%.1f allreduce_share=%.3f a2c_flat_samples_per_s=%.0f "
      "a2c_autograd_samples_per_s=%.0f a2c_speedup=%.2f "
      "ex2_flat_steps_per_s=%.0f ex2_autograd_steps_per_s=%.0f "
      "ex2_torch_steps_per_s=%.0f ex2_speedup=%.2f "
      "ex2_fused_adam_speedup=%.2f adam_floats=%ld adam_flat_steps_per_s=%.0f "
      "adam_torch_steps_per_s=%.0f adam_speedup=%.2f blas=%s\n",
      ppo_rate, bare_rate, ppo_rate / bare_rate, guarded_rate,
      guarded_rate / ppo_rate, dp_rate, dp_rate / ppo_rate,
      two.allreduce_seconds * 1e6, allreduce_share, a2c_flat_rate,
      a2c_autograd_rate, a2c_flat_rate / a2c_autograd_rate, ex2_flat_rate,
      ex2_autograd_rate, ex2_torch_rate, ex2_flat_rate / ex2_autograd_rate,
      ex2_autograd_rate / ex2_torch_rate, static_cast<long>(frame_adam.size()),
      adam_flat_rate, adam_torch_rate, adam_flat_rate / adam_torch_rate,
      blas.kind.c_str());
  return 0;
}

}  // namespace vantage
