#ifndef VANTAGE_COMMON_NET_PORT_FILE_H_
#define VANTAGE_COMMON_NET_PORT_FILE_H_

// A port file: the port a process listens on, one line, written once it
// serves (atomically, so a reader never sees half of it). How a launcher
// or a batch script finds a port the OS chose.

#include <optional>
#include <string>

#include "absl/status/status.h"

namespace vantage {

absl::Status WritePortFile(const std::string& path, int port);
// The port, or nullopt while the file is missing or holds no port.
std::optional<int> ReadPortFile(const std::string& path);

}  // namespace vantage

#endif  // VANTAGE_COMMON_NET_PORT_FILE_H_
