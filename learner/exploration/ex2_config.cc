#include "learner/exploration/ex2_config.h"

#include <algorithm>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "proto/run_config.pb.h"
#include "proto/settings_table.h"

namespace vantage {
namespace {

// EX2's settings, each read from and written to its field; their ranges are
// Validate()'s below, whose messages name the value given.
const SettingsTable<Ex2Config, pb::Ex2Settings>& Ex2Table() {
  using C = Ex2Config;
  static const auto* table = new SettingsTable<Ex2Config, pb::Ex2Settings>(
      "ex2", {{"hidden", &C::hidden},
              {"feature_dim", &C::feature_dim},
              {"learning_rate", &C::learning_rate},
              {"kl_weight", &C::kl_weight},
              {"bonus_coeff", &C::bonus_coeff},
              {"train_iterations", &C::train_iterations},
              {"first_train_iterations", &C::first_train_iterations},
              {"replay_min", &C::replay_min},
              {"replay_size", &C::replay_size},
              {"batch_size", &C::batch_size},
              {"use_actions", &C::use_actions},
              {"encoder", &C::encoder}});
  return *table;
}

}  // namespace

absl::Status Ex2Config::Validate() const {
  if (hidden.empty()) {
    return absl::InvalidArgumentError("ex2.hidden needs at least one size");
  }
  for (int64_t h : hidden) {
    if (h < 1 || h > 4096) {
      return absl::InvalidArgumentError(
          absl::StrCat("ex2.hidden sizes must be in [1, 4096], got ", h));
    }
  }
  if (feature_dim < 1 || feature_dim > 4096) {
    return absl::InvalidArgumentError(absl::StrCat(
        "ex2.feature_dim must be in [1, 4096], got ", feature_dim));
  }
  if (!(learning_rate > 0 && learning_rate < 1)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "ex2.learning_rate must be in (0, 1), got ", learning_rate));
  }
  if (!(kl_weight >= 0 && kl_weight < 1e6)) {
    return absl::InvalidArgumentError(
        absl::StrCat("ex2.kl_weight must be in [0, 1e6), got ", kl_weight));
  }
  if (!(bonus_coeff >= 0 && bonus_coeff < 1e6)) {
    return absl::InvalidArgumentError(
        absl::StrCat("ex2.bonus_coeff must be in [0, 1e6), got ", bonus_coeff));
  }
  if (train_iterations < 1 || first_train_iterations < 1) {
    return absl::InvalidArgumentError(
        "ex2.train_iterations and ex2.first_train_iterations must be >= 1");
  }
  if (batch_size < 1 || batch_size > 1 << 20) {
    return absl::InvalidArgumentError(absl::StrCat(
        "ex2.batch_size must be in [1, 1048576], got ", batch_size));
  }
  // The pool is allocated up front: bounded so that a typo cannot ask for
  // terabytes.
  if (replay_size < 1 || replay_size > 100000000) {
    return absl::InvalidArgumentError(
        absl::StrCat("ex2.replay_size must be in [1, 1e8], got ", replay_size));
  }
  if (replay_min < 1) {
    return absl::InvalidArgumentError(
        absl::StrCat("ex2.replay_min must be >= 1, got ", replay_min));
  }
  const std::vector<std::string> encoders = Ex2EncoderNames();
  if (std::find(encoders.begin(), encoders.end(), encoder) == encoders.end()) {
    return absl::InvalidArgumentError(
        absl::StrCat("ex2.encoder must be one of ",
                     absl::StrJoin(encoders, ", "), ", got '", encoder, "'"));
  }
  return absl::OkStatus();
}

std::vector<std::string> Ex2EncoderNames() { return {"mlp", "conv"}; }

std::vector<std::string> ExplorationNames() { return {"none", "ex2"}; }

std::string ExplorationNameOf(const pb::RunConfig& run) {
  return run.exploration().has_ex2() ? "ex2" : "none";
}

absl::Status SelectExploration(const std::string& name, pb::RunConfig& run) {
  if (name == "none") {
    run.clear_exploration();
  } else if (name == "ex2") {
    run.mutable_exploration()->mutable_ex2();
  } else {
    return absl::InvalidArgumentError(absl::StrCat(
        "unknown exploration method '", name,
        "'; available: ", absl::StrJoin(ExplorationNames(), ", ")));
  }
  return absl::OkStatus();
}

ExplorationConfig ExplorationConfigOf(const pb::RunConfig& run) {
  ExplorationConfig config;
  if (run.exploration().has_ex2()) {
    config.ex2 = FromSettings(run.exploration().ex2());
  }
  return config;
}

void SetExplorationSettings(const ExplorationConfig& config,
                            pb::RunConfig& run) {
  if (!config.ex2.has_value()) {
    run.clear_exploration();
    return;
  }
  ToSettings(*config.ex2, *run.mutable_exploration()->mutable_ex2());
}

Ex2Config FromSettings(const pb::Ex2Settings& settings) {
  Ex2Config config;
  Ex2Table().Read(settings, config);
  return config;
}

void ToSettings(const Ex2Config& config, pb::Ex2Settings& settings) {
  Ex2Table().Write(config, settings);
}

}  // namespace vantage
