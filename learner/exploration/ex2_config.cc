#include "learner/exploration/ex2_config.h"

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"
#include "proto/run_config.pb.h"

namespace vantage {

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
  return absl::OkStatus();
}

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

Ex2Config FromSettings(const pb::Ex2Settings& s) {
  Ex2Config c;
  if (s.hidden_size() > 0)
    c.hidden.assign(s.hidden().begin(), s.hidden().end());
  if (s.has_feature_dim()) c.feature_dim = s.feature_dim();
  if (s.has_learning_rate()) c.learning_rate = s.learning_rate();
  if (s.has_kl_weight()) c.kl_weight = s.kl_weight();
  if (s.has_bonus_coeff()) c.bonus_coeff = s.bonus_coeff();
  if (s.has_train_iterations()) c.train_iterations = s.train_iterations();
  if (s.has_first_train_iterations()) {
    c.first_train_iterations = s.first_train_iterations();
  }
  if (s.has_replay_min()) c.replay_min = s.replay_min();
  if (s.has_replay_size()) c.replay_size = s.replay_size();
  if (s.has_batch_size()) c.batch_size = s.batch_size();
  if (s.has_use_actions()) c.use_actions = s.use_actions();
  return c;
}

void ToSettings(const Ex2Config& c, pb::Ex2Settings& s) {
  s.clear_hidden();
  for (int64_t h : c.hidden) s.add_hidden(h);
  s.set_feature_dim(c.feature_dim);
  s.set_learning_rate(c.learning_rate);
  s.set_kl_weight(c.kl_weight);
  s.set_bonus_coeff(c.bonus_coeff);
  s.set_train_iterations(c.train_iterations);
  s.set_first_train_iterations(c.first_train_iterations);
  s.set_replay_min(c.replay_min);
  s.set_replay_size(c.replay_size);
  s.set_batch_size(c.batch_size);
  s.set_use_actions(c.use_actions);
}

}  // namespace vantage
