#include "actor/run_settings.h"

#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "common/env/frame_stack.h"
#include "proto/settings_table.h"

namespace vantage {
namespace {

// The training section's settings of the actor itself (its env streams,
// --envs, are the run's layout: the distributed or local section decides
// them), of its environments' wrapping and of its policy network (the torso
// is a name, read below).
const SettingsTable<ActorConfig, pb::TrainingSettings>& ActorTable() {
  using C = ActorConfig;
  static const auto* table =
      new SettingsTable<ActorConfig, pb::TrainingSettings>(
          "training",
          {{"env", &C::env},
           {"seed", &C::seed},
           {"segment_length", &C::segment_length}},
          SettingNames::kFlag);
  return *table;
}

const SettingsTable<EnvOptions, pb::TrainingSettings>& EnvOptionsTable() {
  using C = EnvOptions;
  static const auto* table =
      new SettingsTable<EnvOptions, pb::TrainingSettings>(
          "training",
          {{"frame_stack", &C::frame_stack, AtLeast(1),
            AtMost(kMaxFrameStack)}},
          SettingNames::kFlag);
  return *table;
}

const SettingsTable<NetworkConfig, pb::TrainingSettings>& NetworkTable() {
  using C = NetworkConfig;
  static const auto* table =
      new SettingsTable<NetworkConfig, pb::TrainingSettings>(
          "training",
          {{"hidden", &C::hidden}, {"shared_torso", &C::shared_torso}},
          SettingNames::kFlag);
  return *table;
}

// A recurrent core's settings: in a run's config only when it has one, so
// that a feed-forward run's config is what it was before cores existed.
const SettingsTable<NetworkConfig, pb::TrainingSettings>& CoreTable() {
  using C = NetworkConfig;
  static const auto* table =
      new SettingsTable<NetworkConfig, pb::TrainingSettings>(
          "training",
          {{"core_size", &C::core_size, AtLeast(1)},
           {"seq_len", &C::seq_len, AtLeast(0)}},
          SettingNames::kFlag);
  return *table;
}

// The torso by name; the hidden sizes positive.
absl::Status ResolveNetwork(pb::TrainingSettings& training) {
  absl::StatusOr<NetworkConfig> network =
      NetworkTable().Resolve(NetworkConfig(), training);
  if (!network.ok()) return network.status();
  for (int64_t h : network->hidden) {
    if (h < 1) return FlagError("hidden", "sizes must be >= 1");
  }
  if (!training.has_torso()) training.set_torso(TorsoName(network->torso));
  if (!ParseTorso(training.torso()).ok()) {
    return FlagError("torso", absl::StrCat("'", training.torso(),
                                           "' is not one of ", TorsoNames()));
  }
  if (training.has_core() && !ParseCore(training.core()).ok()) {
    return FlagError("core", absl::StrCat("'", training.core(),
                                          "' is not one of none, gru, lstm"));
  }
  if (NamesACore(training)) {
    return CoreTable().Resolve(NetworkConfig(), training).status();
  }
  for (const auto& [given, name] :
       {std::pair{training.has_core_size(), "core_size"},
        std::pair{training.has_seq_len(), "seq_len"}}) {
    if (given) return FlagError(name, "needs a recurrent --core (gru or lstm)");
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status ResolveActorSettings(const ActorConfig& defaults,
                                  pb::TrainingSettings& training) {
  if (absl::Status status = ActorTable().Resolve(defaults, training).status();
      !status.ok()) {
    return status;
  }
  if (absl::Status status = ResolveNetwork(training); !status.ok()) {
    return status;
  }
  return EnvOptionsTable().Resolve(EnvOptions(), training).status();
}

EnvOptions EnvOptionsOf(const pb::RunConfig& run) {
  EnvOptions options;
  EnvOptionsTable().Read(run.training(), options);
  options.python_kwargs = run.training().env_kwargs();
  return options;
}

bool NamesACore(const pb::TrainingSettings& training) {
  return training.has_core() && training.core() != "none";
}

absl::StatusOr<NetworkConfig> PolicyNetworkOf(const pb::RunConfig& run) {
  const pb::TrainingSettings& training = run.training();
  NetworkConfig network;
  NetworkTable().Read(training, network);
  CoreTable().Read(training, network);
  absl::StatusOr<Torso> torso =
      ParseTorso(training.has_torso() ? training.torso() : "mlp");
  if (!torso.ok()) return torso.status();
  network.torso = *torso;
  absl::StatusOr<Core> core =
      ParseCore(training.has_core() ? training.core() : "none");
  if (!core.ok()) return core.status();
  network.core = *core;
  return network;
}

absl::StatusOr<ActorConfig> ActorConfigOf(const pb::RunConfig& run) {
  const pb::TrainingSettings& training = run.training();
  ActorConfig actor;
  ActorTable().Read(training, actor);
  actor.env_options = EnvOptionsOf(run);
  if (training.has_envs()) actor.num_envs = training.envs();
  // The clip bounds normalised observations; unnormalised ones pass as the
  // environment gives them.
  if (training.has_normalize_observations() &&
      !training.normalize_observations()) {
    actor.observation_clip = std::numeric_limits<double>::infinity();
  }
  absl::StatusOr<NetworkConfig> network = PolicyNetworkOf(run);
  if (!network.ok()) return network.status();
  actor.network = *std::move(network);
  return actor;
}

}  // namespace vantage
