#ifndef VANTAGE_LEARNER_EXPLORATION_EX2_CONFIG_H_
#define VANTAGE_LEARNER_EXPLORATION_EX2_CONFIG_H_

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/status.h"

namespace vantage {
namespace pb {
class RunConfig;
class Ex2Settings;
}  // namespace pb

// The amortized exemplar model of EX2 with the settings of its reference
// code for SparseHalfCheetah (exps/halfcheetah.py of jcoreyes/ex2).
struct Ex2Config {
  std::vector<int64_t> hidden = {32};
  int64_t feature_dim = 16;
  double learning_rate = 1e-4;
  double kl_weight = 0.1;
  double bonus_coeff = 1e-3;
  int train_iterations = 2000;
  int first_train_iterations = 5000;
  int64_t replay_min = 10000;
  int64_t replay_size = 250000;
  int batch_size = 128;
  bool use_actions = true;
  // The encoders' trunk (Ex2EncoderNames()): "mlp", or "conv" for image
  // observations (EX2's SiameseConv, its Atari and Doom scripts' model).
  std::string encoder = "mlp";
  bool convolutional() const { return encoder == "conv"; }

  // Names the rule a field breaks as its run-config field (ex2.kl_weight).
  absl::Status Validate() const;
};

std::vector<std::string> Ex2EncoderNames();  // "mlp", "conv"

// The exploration bonus of a run, if it has one.
struct ExplorationConfig {
  std::optional<Ex2Config> ex2;
  bool enabled() const { return ex2.has_value(); }
};

std::vector<std::string> ExplorationNames();  // "none" first
// "none" when the run config has no exploration method.
std::string ExplorationNameOf(const pb::RunConfig& run);
// Selects `name` with its defaults ("none" removes the section); an
// unknown name lists the valid ones.
absl::Status SelectExploration(const std::string& name, pb::RunConfig& run);
// The run config's method over its defaults (not yet validated).
ExplorationConfig ExplorationConfigOf(const pb::RunConfig& run);
// Every field of the method's settings into the run config (none: the
// section removed).
void SetExplorationSettings(const ExplorationConfig& config,
                            pb::RunConfig& run);

Ex2Config FromSettings(const pb::Ex2Settings& settings);
void ToSettings(const Ex2Config& config, pb::Ex2Settings& settings);

}  // namespace vantage

#endif  // VANTAGE_LEARNER_EXPLORATION_EX2_CONFIG_H_
