#include "bench/raw_physics.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include "actor/envs/bullet/bullet_env.h"
#include "actor/envs/bullet/bullet_world.h"
#include "actor/envs/minatar/minatar_env.h"
#include "actor/envs/mujoco/mujoco_env.h"
#include "bench/fastest.h"
#include "common/env/time_limit.h"

namespace vantage {
namespace {

// The bare physics under an environment: its model stepped with kBenchAction on
// every actuator, frame skip included, and nothing of the task around it.

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
    for (int i = 0; i < model_->nu; ++i) data_->ctrl[i] = kBenchAction;
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
    for (double gear : env.gears()) torques_.push_back(gear * kBenchAction);
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

// A MinAtar game's rules with its grid written every step, as the
// environment observes it; each restart seeds a new game.
class MinAtarRules : public RawPhysics {
 public:
  explicit MinAtarRules(std::unique_ptr<MinAtarGame> game)
      : game_(std::move(game)), grid_(game_->channels() * kMinAtarCells) {}

  int frame_skip() const override { return 1; }
  void Restart() override {
    random_.seed(episode_++);
    game_->Reset(random_);
  }
  void Step() override {
    game_->Act(MinAtarAction::kNoop, random_);
    game_->Observe(absl::MakeSpan(grid_));
    benchmark::DoNotOptimize(grid_.data());
  }

 private:
  std::unique_ptr<MinAtarGame> game_;
  std::vector<uint8_t> grid_;
  std::mt19937_64 random_;
  uint64_t episode_ = 0;
};

}  // namespace

std::vector<double> BenchAction(const EnvSpec& spec) {
  if (spec.discrete) return {0.0};
  return std::vector<double>(spec.action_size, kBenchAction);
}

std::unique_ptr<RawPhysics> MakeRawPhysics(const Environment& env) {
  const auto* limited = dynamic_cast<const TimeLimit*>(&env);
  const Environment& inner = limited == nullptr ? env : limited->inner();
  if (const auto* mujoco = dynamic_cast<const MujocoEnv*>(&inner)) {
    return MujocoPhysics::Create(*mujoco);
  }
  if (const auto* bullet = dynamic_cast<const BulletEnv*>(&inner)) {
    return std::make_unique<BulletPhysics>(*bullet);
  }
  if (std::unique_ptr<MinAtarGame> game = MakeBareGame(inner)) {
    return std::make_unique<MinAtarRules>(std::move(game));
  }
  return nullptr;
}

absl::StatusOr<int64_t> FixedActionEpisodeLength(Environment& env) {
  const EnvSpec& spec = env.spec();
  const std::vector<double> action = BenchAction(spec);
  std::vector<double> observation(spec.observation_size);
  uint64_t episode = 0;
  if (absl::Status status = env.Reset(episode, absl::MakeSpan(observation));
      !status.ok()) {
    return status;
  }
  constexpr int kProbeSteps = 3000;
  int episodes_ended = 0;
  for (int t = 0; t < kProbeSteps; ++t) {
    absl::StatusOr<StepResult> result =
        env.Step(action, absl::MakeSpan(observation));
    if (!result.ok() || result->terminated || result->truncated) {
      ++episodes_ended;
      if (absl::Status status =
              env.Reset(++episode, absl::MakeSpan(observation));
          !status.ok()) {
        return status;
      }
    }
  }
  return episodes_ended == 0 ? spec.max_episode_steps
                             : std::max(1, kProbeSteps / episodes_ended);
}

void RegisterRawBenchmark(const std::string& name, RawPhysics& physics,
                          int64_t episode_length) {
  benchmark::RegisterBenchmark(name.c_str(),
                               [&physics, episode_length, steps = int64_t{0}](
                                   benchmark::State& state) mutable {
                                 for (auto _ : state) {
                                   if (steps++ % episode_length == 0)
                                     physics.Restart();
                                   physics.Step();
                                 }
                               })
      ->Apply(UseFastestOfRepetitions);
}

}  // namespace vantage
