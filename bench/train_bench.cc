#include "bench/train_bench.h"

#include <ATen/ATen.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/strings/str_replace.h"
#include "absl/strings/str_split.h"
#include "absl/strings/strip.h"
#include "actor/envs/env_registry.h"
#include "bench/raw_physics.h"
#include "common/nn/compute_threads.h"
#include "common/nn/networks.h"
#include "common/util/self_process.h"
#include "learner/algorithms/a2c/a2c_updater.h"
#include "learner/algorithms/ppo/ppo_updater.h"

namespace vantage {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
      .count();
}

// The fastest of three one-second windows of bare physics steps.
absl::StatusOr<double> RawStepsPerSecond(const std::string& env_name) {
  absl::StatusOr<std::unique_ptr<Environment>> env = MakeEnvironment(env_name);
  if (!env.ok()) return env.status();
  std::unique_ptr<RawPhysics> physics = MakeRawPhysics(**env);
  if (physics == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat(env_name, " has no MuJoCo or Bullet model to time"));
  }
  absl::StatusOr<int64_t> episode = FixedActionEpisodeLength(**env);
  if (!episode.ok()) return episode.status();
  double best = 0.0;
  int64_t steps = 0;
  for (int window = 0; window < 3; ++window) {
    const auto start = std::chrono::steady_clock::now();
    int64_t window_steps = 0;
    while (SecondsSince(start) < 1.0) {
      for (int i = 0; i < 256; ++i, ++steps, ++window_steps) {
        if (steps % *episode == 0) physics->Restart();
        physics->Step();
      }
    }
    best = std::max(best, window_steps / SecondsSince(start));
  }
  return best;
}

// Sample passes per second (rows x epochs) of the fastest of three bare
// updates on a batch of the run's size.
double BareSamplesPerSecond(const BarePpoShape& shape, int64_t batch_size) {
  at::manual_seed(0);
  const UpdateBatch batch = SyntheticBatch(shape, batch_size);
  BarePpo bare(shape);
  bare.Update(batch);  // warm-up
  double fastest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    const auto start = std::chrono::steady_clock::now();
    bare.Update(batch);
    fastest = std::min(fastest, SecondsSince(start));
  }
  return static_cast<double>(batch_size) * shape.epochs / fastest;
}

// A synthetic batch of `streams` envs x `horizon` steps of the run's env,
// its actions drawn by `policy`.
UpdateBatch RunBatch(const TrainBenchConfig& config, int64_t horizon,
                     PolicyNetworkImpl& policy) {
  const int64_t rows = horizon * config.streams;
  UpdateBatch batch;
  batch.horizon = horizon;
  batch.streams = config.streams;
  const EnvSpec& spec = config.spec;
  // Observations as batches hold them: bytes for image tasks.
  batch.observations =
      spec.byte_observations()
          ? at::randint(0, spec.observation_high + 1,
                        {rows, spec.observation_size}, at::kByte)
          : at::randn({rows, spec.observation_size});
  at::NoGradGuard no_grad;
  if (policy.recurrent()) {
    // Chunks of the run's length (whole in the horizon), from zero states,
    // no episode starts.
    batch.seq_len = std::gcd(config.network.seq_len, horizon);
    batch.starts = at::zeros({rows}, at::kBool);
    batch.chunk_states =
        policy.trunk()->InitialState(horizon / batch.seq_len * config.streams);
    const at::Tensor output = policy.Unroll(
        batch.observations, batch.starts.reshape({horizon, config.streams}),
        policy.trunk()->InitialState(config.streams));
    batch.actions =
        policy.Act(output, /*deterministic=*/false, at::Generator());
  } else {
    batch.actions = policy.Act(policy.forward(batch.observations),
                               /*deterministic=*/false, at::Generator());
  }
  batch.behaviour_log_probs = at::randn({rows}) - 2;
  batch.advantages = at::randn({rows});
  batch.returns = at::randn({rows});
  return batch;
}

// Sample passes per second of vantage's own update of the run (PPO's
// `epochs` passes or A2C's one) on the run's networks, the fastest of
// three updates (after a warm-up) of a synthetic batch of the run's envs x
// its horizon: what each env step costs the learner the run uses.
double UpdateSamplesPerSecond(const TrainBenchConfig& config) {
  at::manual_seed(0);
  PolicyNetwork policy(config.spec, config.network);
  ValueNetwork value = MakeValueNetwork(config.spec, config.network, *policy);
  std::unique_ptr<PolicyUpdater> updater;
  int64_t horizon = 0;
  int passes = 1;
  if (config.a2c) {
    horizon = config.a2c_config.horizon();
    updater = std::make_unique<A2cUpdater>(policy, value, config.a2c_config);
  } else {
    PpoConfig ppo;
    ppo.epochs = config.shape.epochs;
    ppo.minibatches = config.shape.minibatches;
    passes = ppo.epochs;
    horizon = std::max<int64_t>(1, config.batch / config.streams);
    updater = std::make_unique<PpoUpdater>(policy, value, ppo);
  }
  const UpdateBatch batch = RunBatch(config, horizon, *policy);
  std::mt19937_64 rng(0);
  updater->Update(batch, 0.999, rng);  // warm-up
  double fastest = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    const auto start = std::chrono::steady_clock::now();
    updater->Update(batch, 0.999, rng);
    fastest = std::min(fastest, SecondsSince(start));
  }
  return static_cast<double>(batch.observations.size(0)) * passes / fastest;
}

struct ProgressPoint {
  double env_steps = 0;
  double elapsed = 0;
};

// env_steps and elapsed_s of every progress.csv row.
std::vector<ProgressPoint> ReadProgress(const std::string& path) {
  std::vector<ProgressPoint> points;
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);  // the header
  while (std::getline(file, line)) {
    const std::vector<std::string> cells = absl::StrSplit(line, ',');
    ProgressPoint point;
    if (cells.size() >= 2 && absl::SimpleAtod(cells[0], &point.env_steps) &&
        absl::SimpleAtod(cells[cells.size() - 2], &point.elapsed)) {
      points.push_back(point);
    }
  }
  return points;
}

// The mean shares of every "<who>: time split over W s: a X%, b Y%, ..."
// line of `log` whose <who> does (learner) or does not (actors) start
// with "learner", by phase name (spaces as underscores), in first-seen
// order.
struct TimeSplit {
  std::vector<std::pair<std::string, double>> shares;
  int processes = 0;
};

TimeSplit ReadTimeSplit(const std::string& log, bool learner) {
  TimeSplit split;
  std::ifstream file(log);
  std::string line;
  constexpr char kMarker[] = ": time split over ";
  while (std::getline(file, line)) {
    const size_t marker = line.find(kMarker);
    if (marker == std::string::npos ||
        absl::StartsWith(line, "learner") != learner) {
      continue;
    }
    const size_t colon = line.find(": ", marker + sizeof(kMarker) - 1);
    if (colon == std::string::npos) continue;
    ++split.processes;
    for (absl::string_view part :
         absl::StrSplit(line.substr(colon + 2), ", ")) {
      const size_t space = part.rfind(' ');
      double share = 0.0;
      if (space == absl::string_view::npos ||
          !absl::SimpleAtod(absl::StripSuffix(part.substr(space + 1), "%"),
                            &share)) {
        continue;
      }
      const std::string name =
          absl::StrReplaceAll(part.substr(0, space), {{" ", "_"}});
      auto found = std::find_if(split.shares.begin(), split.shares.end(),
                                [&](const auto& s) { return s.first == name; });
      if (found == split.shares.end()) {
        split.shares.emplace_back(name, share);
      } else {
        found->second += share;
      }
    }
  }
  for (auto& [name, share] : split.shares)
    share /= std::max(1, split.processes);
  return split;
}

// " prefix_a=1.0 prefix_b=2.0" of `split`.
std::string SplitFields(const TimeSplit& split, const std::string& prefix) {
  std::string fields;
  for (const auto& [name, share] : split.shares) {
    absl::StrAppendFormat(&fields, " %s_%s=%.1f", prefix, name, share);
  }
  return fields;
}

struct Measured {
  double sps = 0.0;
  TimeSplit learner, actors;
};

// Runs `run` as a child `vantage train` and reads its throughput and time
// splits; nullopt (with the reason on stderr) if it failed.
std::optional<Measured> TimeRun(const TrainBenchRun& run) {
  std::error_code error;
  const std::string run_dir =
      absl::StrCat(std::filesystem::temp_directory_path().string(),
                   "/vantage-bench-train-", ::getpid());
  std::filesystem::remove_all(run_dir, error);
  // The run's own output (its RESULT line among it) is not the bench's.
  const std::string log = run_dir + ".log";
  std::filesystem::remove(log, error);
  absl::StatusOr<pid_t> train =
      SpawnSelf({"train", "--config=" + run.config_path, "--run_dir=" + run_dir,
                 "--checkpoint_every=1000000"},
                log);
  if (!train.ok()) return std::nullopt;
  int status = 0;
  waitpid(*train, &status, 0);
  const std::vector<ProgressPoint> points =
      ReadProgress(run_dir + "/progress.csv");
  std::filesystem::remove_all(run_dir, error);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || points.size() < 4) {
    std::fprintf(stderr,
                 "vantage bench train: the run failed or made fewer than 4 "
                 "updates (%zu; its output is in %s); give it more --steps\n",
                 points.size(), log.c_str());
    return std::nullopt;
  }
  Measured measured;
  // Start-up (process launch, the first batch's acting) is not throughput,
  // nor is the end: with --eval_every the last row waits for the final
  // version's evaluation, a one-off cost. Every run is measured alike,
  // from the second row to the one before the last.
  const ProgressPoint& first = points[1];
  const ProgressPoint& last = points[points.size() - 2];
  measured.sps =
      (last.env_steps - first.env_steps) / (last.elapsed - first.elapsed);
  measured.learner = ReadTimeSplit(log, /*learner=*/true);
  measured.actors = ReadTimeSplit(log, /*learner=*/false);
  std::filesystem::remove(log, error);
  return measured;
}

}  // namespace

int RunTrainBenchmark(const TrainBenchConfig& config) {
  SetComputeThreads(1);
  const int cores =
      std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  absl::StatusOr<double> raw = RawStepsPerSecond(config.env);
  if (!raw.ok()) {
    std::fprintf(stderr, "vantage bench train: %s\n",
                 std::string(raw.status().message()).c_str());
    return 2;
  }
  // The update's samples/s and the passes each env step costs of it:
  // vantage's own update, the one the run uses; for PPO the bare LibTorch
  // loop's limit too, for comparison.
  const double update = UpdateSamplesPerSecond(config);
  const int passes = config.a2c ? 1 : config.shape.epochs;
  const auto limit_of = [&](double samples_per_s) {
    return cores / (1.0 / *raw + static_cast<double>(passes) / samples_per_s);
  };
  const double limit = limit_of(update);
  std::printf(
      "train: %s raw physics %.0f steps/s, vantage's %s update %.0f "
      "samples/s (%d passes), %d cores: limit %.0f env steps/s\n",
      config.env.c_str(), *raw, config.a2c ? "A2C" : "PPO", update, passes,
      cores, limit);
  std::string bare_fields;
  if (!config.a2c) {
    const double bare = BareSamplesPerSecond(config.shape, config.batch);
    std::printf(
        "train: with the bare LibTorch PPO loop's %.0f samples/s instead: "
        "limit %.0f env steps/s\n",
        bare, limit_of(bare));
    bare_fields = absl::StrFormat(
        " bare_samples_per_s=%.0f bare_limit_sps=%.0f", bare, limit_of(bare));
  }
  std::fflush(stdout);

  for (const TrainBenchRun& run : config.runs) {
    const std::optional<Measured> measured = TimeRun(run);
    if (!measured.has_value()) return 1;
    const char* mode = run.sync ? "sync" : "async";
    for (const auto& [who, split] : {std::pair<const char*, const TimeSplit*>{
                                         "learner", &measured->learner},
                                     std::pair<const char*, const TimeSplit*>{
                                         "actor", &measured->actors}}) {
      std::string shares;
      for (const auto& [name, share] : split->shares) {
        absl::StrAppendFormat(&shares, "%s%s %.1f%%",
                              shares.empty() ? "" : ", ", name, share);
      }
      std::printf(
          "train: %s (max_policy_lag %ld): %s time split (mean of %d): "
          "%s\n",
          mode, static_cast<long>(run.max_policy_lag), who, split->processes,
          shares.c_str());
    }
    std::printf(
        "RESULT train env=%s algo=%s learners=%d actors=%d envs_per_actor=%d "
        "sync=%d max_policy_lag=%ld sps=%.0f limit_sps=%.0f ratio=%.3f "
        "raw_steps_per_s=%.0f %s=%.0f%s cores=%d%s%s\n",
        config.env.c_str(), config.a2c ? "a2c" : "ppo", config.learners,
        config.actors, config.envs_per_actor, run.sync ? 1 : 0,
        static_cast<long>(run.max_policy_lag), measured->sps, limit,
        measured->sps / limit, *raw,
        config.a2c ? "a2c_update_samples_per_s" : "ppo_update_samples_per_s",
        update, bare_fields.c_str(), cores,
        SplitFields(measured->learner, "learner").c_str(),
        SplitFields(measured->actors, "actor").c_str());
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace vantage
