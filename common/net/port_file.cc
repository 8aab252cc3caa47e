#include "common/net/port_file.h"

#include <cstdio>
#include <fstream>

#include "absl/strings/numbers.h"
#include "absl/strings/str_cat.h"

namespace vantage {

absl::Status WritePortFile(const std::string& path, int port) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream file(temporary, std::ios::trunc);
    file << port << "\n";
    if (!file.flush()) {
      return absl::InternalError(absl::StrCat("cannot write ", temporary));
    }
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    return absl::InternalError(absl::StrCat("cannot write ", path));
  }
  return absl::OkStatus();
}

std::optional<int> ReadPortFile(const std::string& path) {
  std::ifstream file(path);
  std::string line;
  int port = 0;
  if (!std::getline(file, line) || !absl::SimpleAtoi(line, &port) ||
      port <= 0 || port > 65535) {
    return std::nullopt;
  }
  return port;
}

}  // namespace vantage
