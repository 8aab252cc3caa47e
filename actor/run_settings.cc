#include "actor/run_settings.h"

namespace vantage {

EnvOptions EnvOptionsOf(const pb::RunConfig& run) {
  EnvOptions options;
  if (run.training().has_frame_stack()) {
    options.frame_stack = run.training().frame_stack();
  }
  return options;
}

absl::StatusOr<NetworkConfig> PolicyNetworkOf(const pb::RunConfig& run) {
  const pb::TrainingSettings& training = run.training();
  NetworkConfig network;
  network.hidden.assign(training.hidden().begin(), training.hidden().end());
  absl::StatusOr<Torso> torso =
      ParseTorso(training.has_torso() ? training.torso() : "mlp");
  if (!torso.ok()) return torso.status();
  network.torso = *torso;
  network.shared_torso = training.shared_torso();
  return network;
}

}  // namespace vantage
