#ifndef VANTAGE_COMMON_NET_LOOPBACK_PORT_H_
#define VANTAGE_COMMON_NET_LOOPBACK_PORT_H_

#include "absl/status/statusor.h"

namespace vantage {

// A loopback TCP port nobody listens on now: the OS picks it, and it stays
// free until someone binds it, which the caller does next (for servers
// that cannot report a port they chose, such as c10d's rendezvous store).
absl::StatusOr<int> FreeLoopbackPort();

}  // namespace vantage

#endif  // VANTAGE_COMMON_NET_LOOPBACK_PORT_H_
