#include "common/env/environment.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace vantage {

std::string EnvSpec::ActionString() const {
  const std::string kind =
      !discrete ? absl::StrCat("continuous:", action_size)
      : action_nvec.empty()
          ? absl::StrCat("discrete:", action_size)
          : absl::StrCat("multidiscrete:", absl::StrJoin(action_nvec, "x"));
  return absl::StrCat(kind, action_masks ? " masked" : "");
}

int64_t EnvSpec::action_width() const {
  if (!discrete) return action_size;
  return action_nvec.empty() ? 1 : static_cast<int64_t>(action_nvec.size());
}

std::vector<int64_t> EnvSpec::action_heads() const {
  if (!discrete) return {};
  if (action_nvec.empty()) return {action_size};
  return action_nvec;
}

std::string EnvSpec::ObservationString() const {
  if (!observation_keys.empty()) {
    std::vector<std::string> entries;
    for (const ObservationKey& key : observation_keys) {
      entries.push_back(absl::StrCat(
          key.name, ": ",
          key.image() ? absl::StrCat("uint8 ", absl::StrJoin(key.shape, "x"))
                      : absl::StrCat(key.size)));
    }
    return absl::StrCat("dict(", absl::StrJoin(entries, ", "), ")");
  }
  if (observation_shape.empty()) return absl::StrCat(observation_size);
  return absl::StrCat(byte_observations() ? "uint8 " : "",
                      absl::StrJoin(observation_shape, "x"));
}

absl::StatusOr<std::string> Environment::SaveState() const {
  return absl::UnimplementedError(
      absl::StrCat(spec().name, ": this environment cannot save its state"));
}

absl::Status Environment::RestoreState(absl::string_view) {
  return absl::UnimplementedError(absl::StrCat(
      spec().name, ": this environment cannot restore a saved state"));
}

absl::Status Environment::ActionMask(absl::Span<uint8_t>) const {
  return absl::UnimplementedError(
      absl::StrCat(spec().name, ": this environment has no action masks"));
}

absl::StatusOr<Frame> Environment::Render(int, int) {
  return absl::UnimplementedError(
      absl::StrCat(spec().name, ": this environment cannot render"));
}

absl::Status CheckAction(const EnvSpec& spec, absl::Span<const double> action) {
  const size_t expected = spec.action_width();
  if (action.size() != expected) {
    return absl::InvalidArgumentError(
        absl::StrCat(spec.name, ": action has ", action.size(),
                     " values, expected ", expected));
  }
  for (size_t i = 0; i < action.size(); ++i) {
    if (!std::isfinite(action[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          spec.name, ": action[", i, "] is not finite (", action[i], ")"));
    }
  }
  const std::vector<int64_t> heads = spec.action_heads();
  for (size_t i = 0; i < heads.size(); ++i) {
    if (action[i] != std::floor(action[i]) || action[i] < 0 ||
        action[i] >= static_cast<double>(heads[i])) {
      return absl::InvalidArgumentError(
          absl::StrCat(spec.name, ": discrete action ",
                       heads.size() > 1 ? absl::StrCat("value ", i, " ") : "",
                       action[i], " is not an integer in [0, ", heads[i], ")"));
    }
  }
  return absl::OkStatus();
}

absl::Status CheckActionMask(const EnvSpec& spec,
                             absl::Span<const uint8_t> mask) {
  if (!spec.action_masks || !spec.discrete) {
    return absl::InvalidArgumentError(absl::StrCat(
        spec.name, ": an action mask for ", spec.ActionString(),
        " actions, which take none (only masked discrete actions do)"));
  }
  if (mask.size() != static_cast<size_t>(spec.action_size)) {
    return absl::InvalidArgumentError(
        absl::StrCat(spec.name, ": the action mask has ", mask.size(),
                     " entries, expected ", spec.action_size));
  }
  for (size_t i = 0; i < mask.size(); ++i) {
    if (mask[i] > 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(spec.name, ": action mask entry ", i, " is ",
                       static_cast<int>(mask[i]), ", expected 0 or 1"));
    }
  }
  const std::vector<int64_t> heads = spec.action_heads();
  const uint8_t* head = mask.data();
  for (size_t h = 0; h < heads.size(); head += heads[h], ++h) {
    if (std::find(head, head + heads[h], 1) == head + heads[h]) {
      return absl::InvalidArgumentError(
          absl::StrCat(spec.name, ": the action mask is all zero",
                       heads.size() > 1 ? absl::StrCat(" for value ", h) : "",
                       " (no legal action)"));
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<std::vector<uint8_t>> ReadActionMask(const Environment& env) {
  const EnvSpec& spec = env.spec();
  if (!spec.action_masks) return std::vector<uint8_t>();
  std::vector<uint8_t> mask(spec.action_size);
  if (absl::Status status = env.ActionMask(absl::MakeSpan(mask));
      !status.ok()) {
    return status;
  }
  if (absl::Status status = CheckActionMask(spec, mask); !status.ok()) {
    return status;
  }
  return mask;
}

absl::Status CheckStep(const EnvSpec& spec, bool needs_reset,
                       absl::Span<const double> action,
                       absl::Span<double> observation) {
  if (needs_reset) {
    return absl::FailedPreconditionError(
        absl::StrCat(spec.name, ": Reset before stepping"));
  }
  if (absl::Status status = CheckAction(spec, action); !status.ok()) {
    return status;
  }
  return CheckObservationBuffer(spec, observation);
}

absl::Status CheckActionLayout(const EnvSpec& spec) {
  if (spec.action_nvec.empty()) return absl::OkStatus();
  const std::string nvec = absl::StrJoin(spec.action_nvec, "x");
  if (!spec.discrete) {
    return absl::InvalidArgumentError(
        absl::StrCat("spec.action_nvec: ", nvec,
                     " for continuous actions, which have none"));
  }
  int64_t sum = 0;
  for (int64_t choices : spec.action_nvec) {
    // Each bounded before adding, so the sum cannot overflow.
    if (choices < 1 || choices > spec.action_size) {
      return absl::InvalidArgumentError(absl::StrCat(
          "spec.action_nvec: ", nvec, ", expected choices in [1, action_size ",
          spec.action_size, "] each"));
    }
    sum += choices;
    if (sum > spec.action_size) break;
  }
  if (sum != spec.action_size) {
    return absl::InvalidArgumentError(
        absl::StrCat("spec.action_nvec: ", nvec, " sums to ",
                     sum > spec.action_size ? "at least " : "", sum,
                     ", expected action_size ", spec.action_size));
  }
  return absl::OkStatus();
}

namespace {

// One Dict entry's fields, named by its position and key.
absl::Status CheckObservationKey(const ObservationKey& key, size_t index,
                                 int64_t observation_size) {
  const std::string field =
      absl::StrCat("spec.observation_keys[", index, "] (\"", key.name, "\")");
  if (key.name.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(field, ": an empty name"));
  }
  if (key.size < 1 || key.size > observation_size) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ": size ", key.size, ", expected 1..", observation_size));
  }
  if (!key.image()) {
    if (key.high == 0) return absl::OkStatus();
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": high ", key.high, " for a vector"));
  }
  if (key.high < 1 || key.high > 255) {
    return absl::InvalidArgumentError(absl::StrCat(
        field, ": high ", key.high, ", expected 1..255 for an image"));
  }
  int64_t product = 1;
  for (int64_t dimension : key.shape) {
    if (key.shape.size() != 3 || dimension < 1 || dimension > key.size) {
      return absl::InvalidArgumentError(absl::StrCat(
          field, ": shape ", absl::StrJoin(key.shape, "x"),
          ", expected [channels, height, width] holding its size ", key.size));
    }
    product *= dimension;
    if (product > key.size) break;
  }
  if (product != key.size) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, ": shape ", absl::StrJoin(key.shape, "x"),
                     " does not hold its size ", key.size));
  }
  return absl::OkStatus();
}

absl::Status CheckObservationKeys(const EnvSpec& spec) {
  if (!spec.observation_shape.empty() || spec.observation_high != 0) {
    return absl::InvalidArgumentError(
        "spec.observation_keys: a Dict observation is a float row; its "
        "images are described by its entries, not by observation_shape or "
        "observation_high");
  }
  std::set<std::string> names;
  int64_t sum = 0;
  for (size_t i = 0; i < spec.observation_keys.size(); ++i) {
    const ObservationKey& key = spec.observation_keys[i];
    if (absl::Status status =
            CheckObservationKey(key, i, spec.observation_size);
        !status.ok()) {
      return status;
    }
    if (!names.insert(key.name).second) {
      return absl::InvalidArgumentError(absl::StrCat(
          "spec.observation_keys: \"", key.name, "\" appears twice"));
    }
    sum += key.size;
    if (sum > spec.observation_size) break;
  }
  if (sum != spec.observation_size) {
    return absl::InvalidArgumentError(
        absl::StrCat("spec.observation_keys: sizes sum to ",
                     sum > spec.observation_size ? "at least " : "", sum,
                     ", expected observation_size ", spec.observation_size));
  }
  return absl::OkStatus();
}

}  // namespace

absl::Status CheckObservationLayout(const EnvSpec& spec) {
  if (!spec.observation_keys.empty()) return CheckObservationKeys(spec);
  if (spec.observation_high < 0 || spec.observation_high > 255) {
    return absl::InvalidArgumentError(
        absl::StrCat("spec.observation_high: ", spec.observation_high,
                     ", expected 0 (real values) or 1..255 (bytes)"));
  }
  if (spec.observation_shape.empty()) return absl::OkStatus();
  const std::string shape = absl::StrJoin(spec.observation_shape, "x");
  if (spec.observation_shape.size() != 3) {
    return absl::InvalidArgumentError(
        absl::StrCat("spec.observation_shape: ", shape,
                     ", expected [channels, height, width] or nothing"));
  }
  int64_t product = 1;
  for (int64_t dimension : spec.observation_shape) {
    // Each bounded before multiplying, so the product cannot overflow.
    if (dimension < 1 || dimension > spec.observation_size) {
      return absl::InvalidArgumentError(
          absl::StrCat("spec.observation_shape: ", shape,
                       ", expected dimensions in [1, observation_size ",
                       spec.observation_size, "]"));
    }
    product *= dimension;
    if (product > spec.observation_size) break;
  }
  if (product != spec.observation_size) {
    return absl::InvalidArgumentError(absl::StrCat(
        "spec.observation_shape: ", shape, " holds ",
        product > spec.observation_size ? "more than " : "", product,
        " values, expected observation_size ", spec.observation_size));
  }
  return absl::OkStatus();
}

absl::Status CheckObservationBuffer(const EnvSpec& spec,
                                    absl::Span<double> observation) {
  if (observation.size() != static_cast<size_t>(spec.observation_size)) {
    return absl::InvalidArgumentError(absl::StrCat(
        spec.name, ": observation buffer holds ", observation.size(),
        " values, expected ", spec.observation_size));
  }
  return absl::OkStatus();
}

}  // namespace vantage
