#include "actor/envs/env_registry.h"

#include <functional>
#include <map>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "absl/strings/strip.h"
#include "actor/envs/bullet/biped_walk.h"
#include "actor/envs/bullet/bullet_hopper.h"
#include "actor/envs/bullet/terrain_biped.h"
#include "actor/envs/choice/lit_buttons.h"
#include "actor/envs/maze/first_person_maze.h"
#include "actor/envs/memory/cue_recall.h"
#include "actor/envs/minatar/minatar_env.h"
#include "actor/envs/mujoco/gym_tasks.h"
#include "actor/envs/mujoco/humanoid_env.h"
#include "actor/envs/mujoco/pendulum_envs.h"
#include "actor/envs/mujoco/point_maze_env.h"
#include "actor/envs/mujoco/twod_maze_env.h"
#include "actor/envs/python/python_env.h"
#include "common/env/frame_stack.h"
#include "common/env/time_limit.h"

namespace vantage {
namespace {

using Factory = std::function<absl::StatusOr<std::unique_ptr<Environment>>(
    const EnvName& name)>;

// A task that takes no options.
Factory Plain(absl::StatusOr<std::unique_ptr<Environment>> (*make)()) {
  return
      [make](
          const EnvName& name) -> absl::StatusOr<std::unique_ptr<Environment>> {
        if (absl::Status status = ApplyEnvOptions(name.task, {}, name.options);
            !status.ok()) {
          return status;
        }
        return make();
      };
}

const std::map<std::string, Factory>& Factories() {
  static const auto* factories = [] {
    auto* all = new std::map<std::string, Factory>{
        {"BipedWalkFlat", Plain(MakeBipedWalkFlat)},
        {"BipedWalkIncline", Plain(MakeBipedWalkIncline)},
        {"BulletHopper", Plain(MakeBulletHopper)},
        {"CueRecall", MakeCueRecall},
        {"FirstPersonMaze", Plain(MakeFirstPersonMaze)},
        {"Humanoid", Plain(MakeHumanoid)},
        {"InvertedDoublePendulum", Plain(MakeInvertedDoublePendulum)},
        {"InvertedPendulum", MakeInvertedPendulum},
        {"LitButtons", MakeLitButtons},
        {"MinAtarAsterix", Plain(MakeMinAtarAsterix)},
        {"MinAtarBreakout", Plain(MakeMinAtarBreakout)},
        {"MinAtarFreeway", Plain(MakeMinAtarFreeway)},
        {"MinAtarSeaquest", Plain(MakeMinAtarSeaquest)},
        {"MinAtarSpaceInvaders", Plain(MakeMinAtarSpaceInvaders)},
        {"PointMaze", Plain(MakePointMaze)},
        {"TerrainBipedFlat", Plain(MakeTerrainBipedFlat)},
        {"TerrainBipedIncline", Plain(MakeTerrainBipedIncline)},
        {"TwoDMaze", Plain(MakeTwoDMaze)},
    };
    for (const std::string& name : GymTaskNames())
      all->emplace(name, MakeGymTask);
    return all;
  }();
  return *factories;
}

}  // namespace

absl::StatusOr<std::unique_ptr<Environment>> MakeEnvironment(
    absl::string_view name, const EnvOptions& options) {
  absl::StatusOr<std::unique_ptr<Environment>> env;
  absl::string_view path = name;
  if (!options.python_kwargs.empty() && !IsPythonEnvName(name)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "--env_kwargs is for Python environments (python:... or gym:...), "
        "not ",
        name));
  }
  if (IsPythonEnvName(name)) {
    env = MakePythonEnv(name, options.python_kwargs);
  } else if (absl::ConsumePrefix(&path, "mjcf:")) {
    if (path.empty()) {
      return absl::InvalidArgumentError(
          "mjcf: needs a path, e.g. --env=mjcf:/path/model.xml");
    }
    env = MakeMjcfEnv(std::string(path));
  } else {
    absl::StatusOr<EnvName> parsed = ParseEnvName(name);
    if (!parsed.ok()) return parsed.status();
    auto factory = Factories().find(parsed->task);
    if (factory == Factories().end()) {
      return absl::NotFoundError(absl::StrCat(
          "unknown environment '", parsed->task,
          "'; registered: ", absl::StrJoin(RegisteredEnvironments(), ", "),
          ", or mjcf:/path/model.xml, python:MODULE:CALLABLE, gym:ID"));
    }
    env = factory->second(*parsed);
  }
  if (!env.ok()) return env.status();
  auto limited = std::make_unique<TimeLimit>(std::move(*env));
  if (options.frame_stack == 1) return limited;
  return FrameStack::Wrap(std::move(limited), options.frame_stack);
}

std::vector<EnvOptionInfo> EnvironmentOptions(const std::string& name) {
  if (name == "CueRecall") return CueRecallOptions();
  if (name == "InvertedPendulum") return InvertedPendulumOptions();
  if (name == "LitButtons") return LitButtonsOptions();
  return GymTaskOptions(name);
}

std::vector<std::string> RegisteredEnvironments() {
  std::vector<std::string> names;
  for (const auto& entry : Factories()) names.push_back(entry.first);
  return names;
}

}  // namespace vantage
