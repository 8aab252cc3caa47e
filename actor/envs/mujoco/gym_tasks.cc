#include "actor/envs/mujoco/gym_tasks.h"

#include <cmath>
#include <limits>
#include <utility>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "actor/envs/mujoco/locomotion_env.h"
#include "actor/envs/mujoco/models.h"

namespace vantage {
namespace {

absl::StatusOr<std::unique_ptr<Environment>> Build(const LocomotionTask& task,
                                                   const char* xml) {
  absl::StatusOr<MjModelPtr> model = LoadModelFromString(task.name, xml);
  if (!model.ok()) return model.status();
  return MakeLocomotionEnv(task, std::move(*model));
}

LocomotionTask HalfCheetahTask() {
  LocomotionTask task;
  task.name = "HalfCheetah";
  task.frame_skip = 5;  // dt 0.05 s
  task.ctrl_cost = 0.1;
  task.observe_qpos_from = 1;  // 8 + 9 = 17
  task.reset_noise = 0.1;
  task.normal_qvel_noise = true;
  return task;
}

LocomotionTask SparseHalfCheetahTask() {
  LocomotionTask task = HalfCheetahTask();
  task.name = "SparseHalfCheetah";
  task.sparse_x_threshold = 5.0;
  return task;
}

LocomotionTask Ex2SparseHalfCheetahTask() {
  LocomotionTask task = HalfCheetahTask();
  task.name = "Ex2SparseHalfCheetah";
  task.frame_skip = 1;  // rllab's half_cheetah.xml sets none: dt 0.01 s
  task.max_episode_steps = 500;
  task.sparse_x_threshold = 5.0;
  task.sparse_either_way = true;
  task.subtree_com = true;  // 8 + 9 + 3 = 20
  task.qpos_normal_noise = 0.01;
  task.qvel_normal_noise = 0.1;
  return task;
}

LocomotionTask HopperTask() {
  LocomotionTask task;
  task.name = "Hopper";
  task.frame_skip = 4;  // dt 0.008 s
  task.ctrl_cost = 1e-3;
  task.healthy_reward = 1.0;
  task.terminate_when_unhealthy = true;
  task.min_z = 0.7;
  task.angle_index = 2;
  task.min_angle = -0.2;
  task.max_angle = 0.2;
  task.state_limit = 100.0;
  task.observe_qpos_from = 1;  // 5 + 6 = 11
  task.qvel_clip = 10.0;
  task.reset_noise = 5e-3;
  return task;
}

LocomotionTask Walker2dTask() {
  LocomotionTask task;
  task.name = "Walker2d";
  task.frame_skip = 4;  // dt 0.008 s
  task.ctrl_cost = 1e-3;
  task.healthy_reward = 1.0;
  task.terminate_when_unhealthy = true;
  task.min_z = 0.8;
  task.max_z = 2.0;
  task.angle_index = 2;
  task.min_angle = -1.0;
  task.max_angle = 1.0;
  task.observe_qpos_from = 1;  // 8 + 9 = 17
  task.qvel_clip = 10.0;
  task.reset_noise = 5e-3;
  return task;
}

LocomotionTask AntTask() {
  LocomotionTask task;
  task.name = "Ant";
  task.frame_skip = 5;  // dt 0.05 s
  task.ctrl_cost = 0.5;
  task.healthy_reward = 1.0;
  task.terminate_when_unhealthy = true;
  task.min_z = 0.2;
  task.max_z = 1.0;
  task.observe_qpos_from = 2;  // 13 + 14 = 27
  task.reset_noise = 0.1;
  task.normal_qvel_noise = true;
  return task;
}

struct GymTask {
  const char* name;
  LocomotionTask (*task)();
  const char* xml;
};

const std::vector<GymTask>& GymTasks() {
  static const auto* tasks = new std::vector<GymTask>{
      {"Ant", AntTask, kAntXml},
      {"Ex2SparseHalfCheetah", Ex2SparseHalfCheetahTask, kHalfCheetahXml},
      {"HalfCheetah", HalfCheetahTask, kHalfCheetahXml},
      {"Hopper", HopperTask, kHopperXml},
      {"SparseHalfCheetah", SparseHalfCheetahTask, kHalfCheetahXml},
      {"Walker2d", Walker2dTask, kWalker2dXml},
  };
  return *tasks;
}

const GymTask* FindGymTask(absl::string_view name) {
  for (const GymTask& task : GymTasks()) {
    if (task.name == name) return &task;
  }
  return nullptr;
}

// What --env=TASK:KEY=VALUE may change of a locomotion task.
std::vector<EnvOption> LocomotionOptions(LocomotionTask& task) {
  return {
      {"frame_skip", "physics steps per env step", &task.frame_skip, 1},
      {"max_episode_steps", "steps before the time limit truncates (0: none)",
       &task.max_episode_steps, 0},
      {"forward_weight", "reward per metre per second forward",
       &task.forward_weight},
      {"ctrl_cost", "cost per squared action entry", &task.ctrl_cost, 0},
      {"healthy_reward", "reward per step while healthy", &task.healthy_reward},
      {"terminate_when_unhealthy",
       "end the episode when the height or angle rule fails",
       &task.terminate_when_unhealthy},
      {"reset_noise", "scale of the noise added to the initial qpos and qvel",
       &task.reset_noise, 0},
      {"sparse_x_threshold",
       "the sparse reward: 1 per step while the forward body is more than "
       "this far ahead of its start, else 0 (-inf: the dense reward)",
       &task.sparse_x_threshold},
      {"sparse_either_way",
       "the sparse reward pays beyond the threshold either way",
       &task.sparse_either_way},
      {"hide_velocities",
       "observe positions only (partially observable: velocities must be "
       "inferred over time)",
       &task.hide_velocities},
  };
}

absl::Status BadCustomEntry(absl::string_view path, absl::string_view key,
                            absl::string_view why) {
  return absl::InvalidArgumentError(
      absl::StrCat(path, ": <custom> entry '", key, "' ", why));
}

absl::Status ApplyCustomTexts(const mjModel* m, const std::string& path,
                              LocomotionTask& task) {
  for (int i = 0; i < m->ntext; ++i) {
    const std::string key = m->names + m->name_textadr[i];
    const std::string value = m->text_data + m->text_adr[i];
    if (key == "vantage_forward_body") {
      if (mj_name2id(m, mjOBJ_BODY, value.c_str()) < 0) {
        return BadCustomEntry(path, key,
                              absl::StrCat("names body '", value,
                                           "', which the model does not have"));
      }
      task.forward_body = value;
    } else if (absl::StartsWith(key, "vantage_")) {
      return BadCustomEntry(path, key,
                            "is not a vantage text setting (known: "
                            "vantage_forward_body)");
    }
  }
  return absl::OkStatus();
}

// One vantage_ <numeric> entry, with the shape checks its settings share.
struct CustomNumeric {
  const std::string& path;
  std::string key;
  const mjtNum* values;
  int size;

  absl::Status Bad(absl::string_view why) const {
    return BadCustomEntry(path, key, why);
  }

  absl::StatusOr<double> One() const {
    if (size != 1) return Bad("needs exactly one number");
    return values[0];
  }

  // `max` must be exact as a double, so that every value this accepts
  // converts to an integer exactly.
  absl::StatusOr<int64_t> PositiveInteger(int64_t max) const {
    absl::StatusOr<double> value = One();
    if (!value.ok()) return value.status();
    if (*value < 1 || *value > static_cast<double>(max) ||
        *value != std::floor(*value)) {
      return Bad(absl::StrCat("needs a whole number in [1, ", max, "]"));
    }
    return static_cast<int64_t>(*value);
  }
};

// Sets `has_healthy_z` for vantage_healthy_z, whose height rule needs a
// forward body: that can only be checked once every entry is read.
absl::Status ApplyCustomNumeric(const CustomNumeric& entry,
                                LocomotionTask& task, bool& has_healthy_z) {
  const std::string& key = entry.key;
  if (key == "vantage_forward_weight") {
    absl::StatusOr<double> value = entry.One();
    if (!value.ok()) return value.status();
    task.forward_weight = *value;
  } else if (key == "vantage_ctrl_cost") {
    absl::StatusOr<double> value = entry.One();
    if (!value.ok()) return value.status();
    if (*value < 0) return entry.Bad("must be >= 0");
    task.ctrl_cost = *value;
  } else if (key == "vantage_alive_bonus") {
    absl::StatusOr<double> value = entry.One();
    if (!value.ok()) return value.status();
    task.healthy_reward = *value;
  } else if (key == "vantage_healthy_z") {
    if (entry.size != 2 || !(entry.values[0] < entry.values[1])) {
      return entry.Bad("needs two numbers lo < hi");
    }
    task.min_z = entry.values[0];
    task.max_z = entry.values[1];
    task.terminate_when_unhealthy = true;
    has_healthy_z = true;
  } else if (key == "vantage_frame_skip") {
    absl::StatusOr<int64_t> value =
        entry.PositiveInteger(std::numeric_limits<int>::max());
    if (!value.ok()) return value.status();
    task.frame_skip = static_cast<int>(*value);
  } else if (key == "vantage_max_steps") {
    // Above 2^53 not every whole number is a double.
    absl::StatusOr<int64_t> value = entry.PositiveInteger(int64_t{1} << 53);
    if (!value.ok()) return value.status();
    task.max_episode_steps = *value;
  } else {
    return entry.Bad(
        "is not a vantage setting (known: vantage_forward_weight, "
        "vantage_ctrl_cost, vantage_alive_bonus, vantage_healthy_z, "
        "vantage_frame_skip, vantage_max_steps)");
  }
  return absl::OkStatus();
}

// Runs after ApplyCustomTexts: vantage_healthy_z checks the forward body.
absl::Status ApplyCustomNumerics(const mjModel* m, const std::string& path,
                                 LocomotionTask& task) {
  bool has_healthy_z = false;
  for (int i = 0; i < m->nnumeric; ++i) {
    const CustomNumeric entry{path, m->names + m->name_numericadr[i],
                              m->numeric_data + m->numeric_adr[i],
                              m->numeric_size[i]};
    if (!absl::StartsWith(entry.key, "vantage_")) continue;
    for (int j = 0; j < entry.size; ++j) {
      if (!std::isfinite(entry.values[j])) {
        return entry.Bad("has a non-finite value");
      }
    }
    if (absl::Status status = ApplyCustomNumeric(entry, task, has_healthy_z);
        !status.ok()) {
      return status;
    }
  }
  if (has_healthy_z && task.forward_body.empty()) {
    return BadCustomEntry(path, "vantage_healthy_z",
                          "needs vantage_forward_body");
  }
  return absl::OkStatus();
}

}  // namespace

std::vector<std::string> GymTaskNames() {
  std::vector<std::string> names;
  for (const GymTask& task : GymTasks()) names.push_back(task.name);
  return names;
}

absl::StatusOr<std::unique_ptr<Environment>> MakeGymTask(const EnvName& name) {
  const GymTask* entry = FindGymTask(name.task);
  if (entry == nullptr) {
    return absl::NotFoundError(
        absl::StrCat(name.task, " is no Gymnasium locomotion task"));
  }
  LocomotionTask task = entry->task();
  if (absl::Status status =
          ApplyEnvOptions(name.task, LocomotionOptions(task), name.options);
      !status.ok()) {
    return status;
  }
  task.name = name.Canonical();
  return Build(task, entry->xml);
}

std::vector<EnvOptionInfo> GymTaskOptions(const std::string& name) {
  const GymTask* entry = FindGymTask(name);
  if (entry == nullptr) return {};
  LocomotionTask task = entry->task();
  return Describe(LocomotionOptions(task));
}

absl::StatusOr<std::unique_ptr<Environment>> MakeMjcfEnv(
    const std::string& path) {
  absl::StatusOr<MjModelPtr> loaded = LoadModelFromFile(path);
  if (!loaded.ok()) return loaded.status();
  const mjModel* m = loaded->get();
  LocomotionTask task;
  task.name = absl::StrCat("mjcf:", path);
  task.forward_body.clear();
  if (absl::Status status = ApplyCustomTexts(m, path, task); !status.ok()) {
    return status;
  }
  if (absl::Status status = ApplyCustomNumerics(m, path, task); !status.ok()) {
    return status;
  }
  if (m->nu == 0) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": the model has no actuators to control"));
  }
  return MakeLocomotionEnv(task, std::move(*loaded));
}

}  // namespace vantage
