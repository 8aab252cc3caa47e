#include "deploy/cli/resolved_run_configs.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "absl/status/statusor.h"
#include "absl/strings/str_cat.h"
#include "deploy/run/run_config.h"
#include "deploy/run/run_config_file.h"
#include "google/protobuf/struct.pb.h"
#include "google/protobuf/util/json_util.h"

namespace vantage {
namespace {

namespace fs = std::filesystem;

// `text` as a JSON string literal, quotes and escapes included.
std::string JsonStringLiteral(const std::string& text) {
  google::protobuf::Value value;
  value.set_string_value(text);
  std::string json;
  if (!google::protobuf::util::MessageToJsonString(value, &json).ok()) {
    return "";
  }
  return json;
}

// Appends `"real path": {resolved config}` for the run in `directory`, if
// it holds a config this vantage resolves; false when it holds no run.
bool AddRun(const fs::path& directory, std::string& object) {
  std::error_code error;
  const fs::path config_path = directory / "config.json";
  if (!fs::is_regular_file(config_path, error)) return false;
  absl::StatusOr<pb::RunConfig> config =
      ReadRunConfigFile(config_path.string());
  if (config.ok()) config = ResolveRunConfig(*config);
  if (!config.ok()) return true;
  const std::string key =
      JsonStringLiteral(fs::weakly_canonical(directory, error).string());
  if (key.empty() || error) return true;
  absl::StrAppend(&object, object.size() > 1 ? "," : "", key, ":",
                  RunConfigToJson(*config));
  return true;
}

bool WriteAll(int fd, const std::string& text) {
  size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = write(fd, text.data() + written, text.size() - written);
    if (n <= 0) return false;
    written += static_cast<size_t>(n);
  }
  return true;
}

}  // namespace

void ExportResolvedRunConfigs(const std::vector<std::string>& arguments) {
  unsetenv(kResolvedRunConfigsVariable);
  std::string object = "{";
  for (const std::string& argument : arguments) {
    std::error_code error;
    if (argument.empty() || argument[0] == '-' ||
        !fs::is_directory(argument, error)) {
      continue;
    }
    // A run's own folders (checkpoints) hold no runs, as the scripts see it.
    if (AddRun(argument, object)) continue;
    for (fs::recursive_directory_iterator
             it(argument, fs::directory_options::skip_permission_denied, error),
         end;
         !error && it != end; it.increment(error)) {
      if (it->is_directory(error) && AddRun(it->path(), object)) {
        it.disable_recursion_pending();
      }
    }
  }
  if (object.size() == 1) return;
  object += "}";
  // Not close-on-exec: the script reads it through /proc/self/fd.
  const int fd = memfd_create("vantage-resolved-run-configs", 0);
  if (fd < 0) return;
  if (!WriteAll(fd, object)) {
    close(fd);
    return;
  }
  setenv(kResolvedRunConfigsVariable,
         absl::StrCat("/proc/self/fd/", fd).c_str(), 1);
}

}  // namespace vantage
