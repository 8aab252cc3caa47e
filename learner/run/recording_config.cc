#include "learner/run/recording_config.h"

#include "proto/run_config.pb.h"
#include "proto/settings_table.h"

namespace vantage {
namespace {

const SettingsTable<RecordingConfig, pb::RecordingSettings>& RecordingTable() {
  using C = RecordingConfig;
  static const auto* table =
      new SettingsTable<RecordingConfig, pb::RecordingSettings>(
          "recording",
          {{"checkpoint_every", &C::checkpoint_every, AtLeast(1)},
           {"keep_checkpoints", &C::keep_checkpoints, AtLeast(1)}},
          SettingNames::kFlag);
  return *table;
}

}  // namespace

absl::Status RecordingConfig::Validate() const {
  return RecordingTable().Validate(*this);
}

absl::Status ResolveRecordingSettings(pb::RecordingSettings& settings) {
  return RecordingTable().Resolve(RecordingConfig(), settings).status();
}

RecordingConfig RecordingConfigOf(const pb::RecordingSettings& settings) {
  RecordingConfig config;
  RecordingTable().Read(settings, config);
  return config;
}

}  // namespace vantage
