#include "actor/envs/mujoco/mujoco_model.h"

#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>

#include "absl/strings/str_cat.h"

namespace vantage {
namespace {

class MujocoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// MuJoCo calls this instead of exiting; unwinding through MuJoCo's frames
// is fine on x86-64 Linux, where every frame has unwind tables.
void ThrowMujocoError(const char* message) { throw MujocoError(message); }

thread_local std::string last_warning;
void RecordMujocoWarning(const char* message) { last_warning = message; }

void InstallHandlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = ThrowMujocoError;
    mju_user_warning = RecordMujocoWarning;
  });
}

}  // namespace

absl::Status GuardMujoco(absl::FunctionRef<void()> fn) {
  InstallHandlers();
  try {
    fn();
  } catch (const MujocoError& error) {
    return absl::InternalError(absl::StrCat("MuJoCo error: ", error.what()));
  }
  return absl::OkStatus();
}

absl::StatusOr<MjModelPtr> LoadModelFromString(absl::string_view name,
                                               absl::string_view xml) {
  InstallHandlers();
  // mjVFS is large (megabytes): keep it off the stack.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const std::string filename = absl::StrCat(name, ".xml");
  if (mj_makeEmptyFileVFS(vfs.get(), filename.c_str(),
                          static_cast<int>(xml.size())) != 0) {
    return absl::InternalError(
        absl::StrCat("cannot add model '", name, "' to MuJoCo's VFS"));
  }
  const int index = mj_findFileVFS(vfs.get(), filename.c_str());
  std::memcpy(vfs->filedata[index], xml.data(), xml.size());
  char error[1000] = "";
  mjModel* model = nullptr;
  absl::Status guarded = GuardMujoco([&] {
    model = mj_loadXML(filename.c_str(), vfs.get(), error, sizeof(error));
  });
  mj_deleteVFS(vfs.get());
  if (!guarded.ok()) return guarded;
  if (model == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("model '", name, "' does not compile: ", error));
  }
  return MjModelPtr(model);
}

absl::StatusOr<MjModelPtr> LoadModelFromFile(const std::string& path) {
  char error[1000] = "";
  mjModel* model = nullptr;
  absl::Status guarded = GuardMujoco(
      [&] { model = mj_loadXML(path.c_str(), nullptr, error, sizeof(error)); });
  if (!guarded.ok()) return guarded;
  if (model == nullptr) {
    return absl::InvalidArgumentError(
        absl::StrCat("cannot load MJCF '", path, "': ", error));
  }
  return MjModelPtr(model);
}

absl::StatusOr<MjDataPtr> MakeData(const mjModel* model) {
  mjData* data = nullptr;
  absl::Status guarded = GuardMujoco([&] { data = mj_makeData(model); });
  if (!guarded.ok()) return guarded;
  if (data == nullptr)
    return absl::ResourceExhaustedError("mj_makeData failed");
  return MjDataPtr(data);
}

absl::StatusOr<LoadedModel> LoadModelAndData(absl::string_view name,
                                             absl::string_view xml) {
  absl::StatusOr<MjModelPtr> model = LoadModelFromString(name, xml);
  if (!model.ok()) return model.status();
  absl::StatusOr<MjDataPtr> data = MakeData(model->get());
  if (!data.ok()) return data.status();
  return LoadedModel{std::move(*model), std::move(*data)};
}

}  // namespace vantage
