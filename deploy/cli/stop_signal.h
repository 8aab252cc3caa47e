#ifndef VANTAGE_DEPLOY_CLI_STOP_SIGNAL_H_
#define VANTAGE_DEPLOY_CLI_STOP_SIGNAL_H_

#include <atomic>

namespace vantage {

// Set once SIGINT or SIGTERM arrives (the handlers are installed on the
// first call), so long-running commands can end cleanly.
const std::atomic<bool>& StopRequested();

}  // namespace vantage

#endif  // VANTAGE_DEPLOY_CLI_STOP_SIGNAL_H_
