#ifndef VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_MODEL_H_
#define VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_MODEL_H_

// RAII handles for MuJoCo models and data, model loading from embedded text
// or files, and MuJoCo errors turned into absl::Status.

#include <mujoco/mujoco.h>

#include <memory>
#include <string>

#include "absl/functional/function_ref.h"
#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace vantage {

struct MjModelDeleter {
  void operator()(mjModel* model) const { mj_deleteModel(model); }
};
struct MjDataDeleter {
  void operator()(mjData* data) const { mj_deleteData(data); }
};
using MjModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using MjDataPtr = std::unique_ptr<mjData, MjDataDeleter>;

// Compiles MJCF text held in memory, through MuJoCo's virtual file system,
// so that models built into the binary need no file next to it.
absl::StatusOr<MjModelPtr> LoadModelFromString(absl::string_view name,
                                               absl::string_view xml);

// Compiles an MJCF file from disk.
absl::StatusOr<MjModelPtr> LoadModelFromFile(const std::string& path);

absl::StatusOr<MjDataPtr> MakeData(const mjModel* model);

// A compiled built-in model with its data, ready for an environment.
struct LoadedModel {
  MjModelPtr model;
  MjDataPtr data;
};
absl::StatusOr<LoadedModel> LoadModelAndData(absl::string_view name,
                                             absl::string_view xml);

// Runs `fn` with mju_user_error turned into an Internal error instead of
// MuJoCo's default exit(); MuJoCo warnings are recorded, not printed.
absl::Status GuardMujoco(absl::FunctionRef<void()> fn);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_MUJOCO_MUJOCO_MODEL_H_
