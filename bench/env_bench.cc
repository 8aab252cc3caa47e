#include "bench/env_bench.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "actor/envs/bullet/bullet_env.h"
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

// The bare physics under an environment: its model stepped with kAction on
// every actuator, frame skip included, and nothing of the task around it.
class RawPhysics {
 public:
  virtual ~RawPhysics() = default;
  virtual int frame_skip() const = 0;
  // Back to the model's initial state.
  virtual void Restart() = 0;
  // One environment step's worth of physics.
  virtual void Step() = 0;
};

class MujocoPhysics : public RawPhysics {
 public:
  MujocoPhysics(const MujocoEnv& env, MjDataPtr data)
      : model_(mj_copyModel(nullptr, env.model())),
        data_(std::move(data)),
        frame_skip_(env.frame_skip()) {}

  static std::unique_ptr<RawPhysics> Create(const MujocoEnv& env) {
    absl::StatusOr<MjDataPtr> data = MakeData(env.model());
    if (!data.ok()) return nullptr;
    return std::make_unique<MujocoPhysics>(env, std::move(*data));
  }

  int frame_skip() const override { return frame_skip_; }
  void Restart() override {
    mj_resetData(model_.get(), data_.get());
    for (int i = 0; i < model_->nu; ++i) data_->ctrl[i] = kAction;
    mj_forward(model_.get(), data_.get());
  }
  void Step() override {
    for (int i = 0; i < frame_skip_; ++i) mj_step(model_.get(), data_.get());
  }

 private:
  MjModelPtr model_;
  MjDataPtr data_;
  int frame_skip_;
};

// Restarts by putting the same world back into the zero pose, which is
// cheaper than the environment's fresh world per episode: the ratio
// includes that cost.
class BulletPhysics : public RawPhysics {
 public:
  explicit BulletPhysics(const BulletEnv& env)
      : world_(env.model()),
        pose_(env.ZeroPose()),
        rest_(pose_.size(), 0.0),
        frame_skip_(env.frame_skip()) {
    for (double gear : env.gears()) torques_.push_back(gear * kAction);
  }

  int frame_skip() const override { return frame_skip_; }
  void Restart() override { world_.SetState(pose_, rest_); }
  void Step() override { world_.Step(torques_, frame_skip_); }

 private:
  BulletWorld world_;
  std::vector<double> pose_;
  std::vector<double> rest_;
  std::vector<double> torques_;
  int frame_skip_;
};

// nullptr if the environment (inside its time limit) has no physics engine
// this benchmark knows.
std::unique_ptr<RawPhysics> MakeRawPhysics(const Environment& env) {
  const auto* limited = dynamic_cast<const TimeLimit*>(&env);
  const Environment& inner = limited == nullptr ? env : limited->inner();
  if (const auto* mujoco = dynamic_cast<const MujocoEnv*>(&inner)) {
    return MujocoPhysics::Create(*mujoco);
  }
  if (const auto* bullet = dynamic_cast<const BulletEnv*>(&inner)) {
    return std::make_unique<BulletPhysics>(*bullet);
  }
  return nullptr;
}

}  // namespace

int RunEnvBenchmark(const std::string& env_name) {
  absl::StatusOr<std::unique_ptr<Environment>> made = MakeEnvironment(env_name);
  if (!made.ok()) {
    std::fprintf(stderr, "vantage bench env: %s\n",
                 std::string(made.status().message()).c_str());
    return 2;
  }
  std::unique_ptr<RawPhysics> physics = MakeRawPhysics(**made);
  if (physics == nullptr) {
    std::fprintf(stderr,
                 "vantage bench env: %s has no MuJoCo or Bullet model to "
                 "compare with\n",
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

  // The baseline: the same model stepped bare, restarted as often.
  const int frame_skip = physics->frame_skip();
  int64_t raw_steps = 0;
  benchmark::RegisterBenchmark("raw", [&](benchmark::State& state) {
    for (auto _ : state) {
      if (raw_steps++ % episode_length == 0) physics->Restart();
      physics->Step();
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
