#include "bench/env_bench.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "actor/envs/env_registry.h"
#include "actor/envs/mujoco/mujoco_env.h"
#include "actor/vector_env.h"
#include "bench/fastest.h"
#include "common/env/time_limit.h"

namespace vantage {
namespace {

constexpr int kVectorEnvs = 16;
// A fixed, in-bounds action for every actuator: the same work each step.
constexpr double kAction = 0.2;

}  // namespace

int RunEnvBenchmark(const std::string& env_name) {
  absl::StatusOr<std::unique_ptr<Environment>> made = MakeEnvironment(env_name);
  if (!made.ok()) {
    std::fprintf(stderr, "vantage bench env: %s\n",
                 std::string(made.status().message()).c_str());
    return 2;
  }
  const auto* limited = dynamic_cast<const TimeLimit*>(made->get());
  const auto* mujoco = limited == nullptr
                           ? nullptr
                           : dynamic_cast<const MujocoEnv*>(&limited->inner());
  if (mujoco == nullptr) {
    std::fprintf(stderr,
                 "vantage bench env: %s has no MuJoCo model to compare with\n",
                 env_name.c_str());
    return 2;
  }
  Environment& env = **made;
  const EnvSpec spec = env.spec();
  const std::vector<double> action(spec.action_size, kAction);

  // How long the fixed action's episodes last: the baseline restarts its
  // physics as often, so both sides simulate the same kind of states (a
  // fallen body in permanent contact steps at another speed).
  std::vector<double> observation(spec.observation_size);
  uint64_t episode = 0;
  if (!env.Reset(episode, absl::MakeSpan(observation)).ok()) return 1;
  constexpr int kProbeSteps = 3000;
  int episodes_ended = 0;
  for (int t = 0; t < kProbeSteps; ++t) {
    absl::StatusOr<StepResult> result =
        env.Step(action, absl::MakeSpan(observation));
    if (!result.ok() || result->terminated || result->truncated) {
      ++episodes_ended;
      if (!env.Reset(++episode, absl::MakeSpan(observation)).ok()) return 1;
    }
  }
  const int64_t episode_length =
      episodes_ended == 0 ? spec.max_episode_steps
                          : std::max(1, kProbeSteps / episodes_ended);

  // The baseline: the same model stepped bare, reset as often.
  MjModelPtr raw_model(mj_copyModel(nullptr, mujoco->model()));
  absl::StatusOr<MjDataPtr> raw_data = MakeData(raw_model.get());
  if (!raw_data.ok()) return 1;
  mjData* d = raw_data->get();
  const int frame_skip = mujoco->frame_skip();
  int64_t raw_steps = 0;
  benchmark::RegisterBenchmark("raw", [&](benchmark::State& state) {
    for (auto _ : state) {
      if (raw_steps++ % episode_length == 0) {
        mj_resetData(raw_model.get(), d);
        for (int i = 0; i < raw_model->nu; ++i) d->ctrl[i] = kAction;
        mj_forward(raw_model.get(), d);
      }
      for (int i = 0; i < frame_skip; ++i) mj_step(raw_model.get(), d);
    }
  })->Apply(UseFastestOfRepetitions);

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
      VectorEnv::Create(env_name, kVectorEnvs, 0);
  if (!vector.ok() || !(*vector)->Reset().ok()) return 1;
  const std::vector<double> actions(kVectorEnvs * spec.action_size, kAction);
  benchmark::RegisterBenchmark("vec16", [&](benchmark::State& state) {
    for (auto _ : state) benchmark::DoNotOptimize((*vector)->Step(actions));
  })->Apply(UseFastestOfRepetitions);

  std::printf(
      "env %s: frame skip %d, one thread, episodes of %ld steps under the "
      "fixed action\n",
      env_name.c_str(), frame_skip, static_cast<long>(episode_length));
  FastestCollector collector;
  benchmark::RunSpecifiedBenchmarks(&collector);
  const double raw = 1.0 / collector.Seconds("raw");
  const double stepped = 1.0 / collector.Seconds("env");
  const double vec16 = kVectorEnvs / collector.Seconds("vec16");
  std::printf(
      "RESULT env name=%s raw_steps_per_s=%.0f env_steps_per_s=%.0f "
      "vec16_steps_per_s=%.0f ratio=%.3f\n",
      env_name.c_str(), raw, stepped, vec16, vec16 / raw);
  return 0;
}

}  // namespace vantage
