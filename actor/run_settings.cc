#include "actor/run_settings.h"

namespace vantage {

EnvOptions EnvOptionsOf(const pb::RunConfig& run) {
  EnvOptions options;
  if (run.training().has_frame_stack()) {
    options.frame_stack = run.training().frame_stack();
  }
  options.python_kwargs = run.training().env_kwargs();
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

absl::StatusOr<ActorConfig> ActorConfigOf(const pb::RunConfig& run) {
  const pb::TrainingSettings& training = run.training();
  ActorConfig actor;
  actor.env = training.env();
  actor.env_options = EnvOptionsOf(run);
  if (training.has_envs()) actor.num_envs = training.envs();
  if (training.has_segment_length()) {
    actor.segment_length = training.segment_length();
  }
  actor.seed = training.seed();
  absl::StatusOr<NetworkConfig> network = PolicyNetworkOf(run);
  if (!network.ok()) return network.status();
  actor.network = *std::move(network);
  return actor;
}

}  // namespace vantage
