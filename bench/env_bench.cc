#include "bench/env_bench.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "actor/envs/env_registry.h"
#include "actor/envs/python/python_env.h"
#include "actor/vector_env.h"
#include "bench/fastest.h"
#include "bench/raw_physics.h"
#include "common/env/time_limit.h"

namespace vantage {
namespace {

constexpr int kVectorEnvs = 16;

// The fastest of five timed plain Python loops of the environment under the
// benchmark's action, as the benchmarks keep the fastest repetition.
absl::StatusOr<double> FastestPlainPythonLoop(
    const std::string& env_name, const std::string& env_kwargs,
    const std::vector<double>& action) {
  double fastest = 0.0;
  for (int repetition = 0; repetition < 5; ++repetition) {
    absl::StatusOr<double> rate =
        PlainPythonStepsPerSecond(env_name, env_kwargs, action, 20000);
    if (!rate.ok()) return rate.status();
    fastest = std::max(fastest, *rate);
  }
  return fastest;
}

}  // namespace

int RunEnvBenchmark(const std::string& env_name,
                    const std::string& env_kwargs) {
  EnvOptions options;
  options.python_kwargs = env_kwargs;
  absl::StatusOr<std::unique_ptr<Environment>> made =
      MakeEnvironment(env_name, options);
  if (!made.ok()) {
    std::fprintf(stderr, "vantage bench env: %s\n",
                 std::string(made.status().message()).c_str());
    return 2;
  }
  // Without a bare engine (the raycast maze: its picture is the work)
  // only the environment's own rates are measured.
  std::unique_ptr<RawPhysics> physics = MakeRawPhysics(**made);
  Environment& env = **made;
  const EnvSpec spec = env.spec();
  const std::vector<double> action = BenchAction(spec);

  absl::StatusOr<int64_t> episode_length = FixedActionEpisodeLength(env);
  if (!episode_length.ok()) return 1;
  if (physics != nullptr) {
    RegisterRawBenchmark("raw", *physics, *episode_length);
  }

  std::vector<double> observation(spec.observation_size);
  uint64_t episode = 1 << 20;  // seeds the probe did not use
  if (!env.Reset(episode, absl::MakeSpan(observation)).ok()) return 1;
  benchmark::RegisterBenchmark("env", [&](benchmark::State& state) {
    for (auto _ : state) {
      absl::StatusOr<StepResult> result =
          env.Step(action, absl::MakeSpan(observation));
      if (!result.ok() || result->terminated || result->truncated) {
        (void)env.Reset(++episode, absl::MakeSpan(observation));
      }
    }
  })->Apply(UseFastestOfRepetitions);

  absl::StatusOr<std::unique_ptr<VectorEnv>> vector =
      VectorEnv::Create(env_name, kVectorEnvs, 0, options);
  if (!vector.ok() || !(*vector)->Reset().ok()) return 1;
  std::vector<double> actions;
  for (int i = 0; i < kVectorEnvs; ++i) {
    actions.insert(actions.end(), action.begin(), action.end());
  }
  benchmark::RegisterBenchmark("vec16", [&](benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize((*vector)->Step(actions));
  })->Apply(UseFastestOfRepetitions);

  if (physics == nullptr) {
    std::printf(
        "env %s: one thread, episodes of %ld steps under the fixed action; "
        "no bare engine to compare with\n",
        env_name.c_str(), static_cast<long>(*episode_length));
  } else {
    std::printf(
        "env %s: frame skip %d, one thread, episodes of %ld steps under the "
        "fixed action\n",
        env_name.c_str(), physics->frame_skip(),
        static_cast<long>(*episode_length));
  }
  FastestCollector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  const double stepped = 1.0 / collector.Seconds("env");
  const double vec16 = kVectorEnvs / collector.Seconds("vec16");
  if (IsPythonEnvName(env_name)) {
    absl::StatusOr<double> plain =
        FastestPlainPythonLoop(env_name, env_kwargs, action);
    if (!plain.ok()) {
      std::fprintf(stderr, "vantage bench env: %s\n",
                   std::string(plain.status().message()).c_str());
      return 1;
    }
    std::printf(
        "RESULT env name=%s python_steps_per_s=%.0f env_steps_per_s=%.0f "
        "vec16_steps_per_s=%.0f ratio=%.3f\n",
        env_name.c_str(), *plain, stepped, vec16, stepped / *plain);
    return 0;
  }
  if (physics == nullptr) {
    std::printf(
        "RESULT env name=%s env_steps_per_s=%.0f vec16_steps_per_s=%.0f\n",
        env_name.c_str(), stepped, vec16);
    return 0;
  }
  const double raw = 1.0 / collector.Seconds("raw");
  std::printf(
      "RESULT env name=%s raw_steps_per_s=%.0f env_steps_per_s=%.0f "
      "vec16_steps_per_s=%.0f ratio=%.3f\n",
      env_name.c_str(), raw, stepped, vec16, vec16 / raw);
  return 0;
}

}  // namespace vantage
