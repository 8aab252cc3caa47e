#include "common/util/self_process.h"

#include <fcntl.h>
#include <unistd.h>

#include <filesystem>

namespace vantage {

absl::StatusOr<pid_t> SpawnSelf(const std::vector<std::string>& args,
                                const std::string& output_path, bool append) {
  std::error_code error;
  const std::string self =
      std::filesystem::read_symlink("/proc/self/exe", error).string();
  if (error) return absl::InternalError("cannot find this binary");
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(self.c_str()));
  for (const std::string& arg : args) {
    argv.push_back(const_cast<char*>(arg.c_str()));
  }
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return absl::InternalError("fork failed");
  if (pid == 0) {
    if (!output_path.empty()) {
      const int fd =
          open(output_path.c_str(),
               O_WRONLY | O_CREAT | (append ? O_APPEND : O_TRUNC), 0644);
      if (fd < 0) _exit(127);
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      close(fd);
    }
    // By /proc/self/exe rather than its path: the file this process runs,
    // even when a rebuild has replaced or removed the one at the path, so
    // the children of a long run (an experiment's cells, a distributed
    // run's restarted actors) run the code it started with, or run at all.
    execv("/proc/self/exe", argv.data());
    _exit(127);
  }
  return pid;
}

}  // namespace vantage
