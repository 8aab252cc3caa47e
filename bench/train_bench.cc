#include "bench/train_bench.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>
#include <vector>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "actor/envs/env_registry.h"
#include "bench/raw_physics.h"
#include "common/util/self_process.h"

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

}  // namespace

int RunTrainBenchmark(const TrainBenchConfig& config) {
  at::set_num_threads(1);
  const int cores =
      std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  absl::StatusOr<double> raw = RawStepsPerSecond(config.env);
  if (!raw.ok()) {
    std::fprintf(stderr, "vantage bench train: %s\n",
                 std::string(raw.status().message()).c_str());
    return 2;
  }
  const double bare = BareSamplesPerSecond(config.shape, config.batch);
  const double limit =
      cores / (1.0 / *raw + static_cast<double>(config.shape.epochs) / bare);
  std::printf(
      "train: %s raw physics %.0f steps/s, bare PPO update %.0f samples/s "
      "(%d epochs), %d cores: limit %.0f env steps/s\n",
      config.env.c_str(), *raw, bare, config.shape.epochs, cores, limit);
  std::fflush(stdout);

  std::error_code error;
  const std::string run_dir =
      absl::StrCat(std::filesystem::temp_directory_path().string(),
                   "/vantage-bench-train-", ::getpid());
  std::filesystem::remove_all(run_dir, error);
  // The run's own output (its RESULT line among it) is not the bench's.
  const std::string log = run_dir + ".log";
  absl::StatusOr<pid_t> train =
      SpawnSelf({"train", "--config=" + config.config_path,
                 "--run_dir=" + run_dir, "--checkpoint_every=1000000"},
                log);
  if (!train.ok()) return 1;
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
    return 1;
  }
  std::filesystem::remove(log, error);
  // Start-up (process launch, the first batch's acting) is not throughput.
  const ProgressPoint& first = points[1];
  const ProgressPoint& last = points.back();
  const double sps =
      (last.env_steps - first.env_steps) / (last.elapsed - first.elapsed);
  std::printf(
      "RESULT train env=%s learners=%d actors=%d envs_per_actor=%d sync=%d "
      "sps=%.0f limit_sps=%.0f ratio=%.3f raw_steps_per_s=%.0f "
      "bare_samples_per_s=%.0f cores=%d\n",
      config.env.c_str(), config.learners, config.actors, config.envs_per_actor,
      config.sync ? 1 : 0, sps, limit, sps / limit, *raw, bare, cores);
  return 0;
}

}  // namespace vantage
