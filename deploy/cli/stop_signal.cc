#include "deploy/cli/stop_signal.h"

#include <csignal>

namespace vantage {
namespace {

std::atomic<bool> stop{false};

extern "C" void OnStopSignal(int /*signal*/) { stop = true; }

}  // namespace

const std::atomic<bool>& StopRequested() {
  static const bool installed = [] {
    struct sigaction action = {};
    action.sa_handler = OnStopSignal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    return true;
  }();
  (void)installed;
  return stop;
}

}  // namespace vantage
