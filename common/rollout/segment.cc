#include "common/rollout/segment.h"

#include <ATen/ATen.h>

#include <cmath>
#include <string>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace vantage {
namespace {

std::string Shape(const at::Tensor& t) {
  return absl::StrCat("[", absl::StrJoin(t.sizes(), ", "), "]");
}

absl::Status Expect(const at::Tensor& t, const char* field,
                    std::vector<int64_t> shape, at::ScalarType dtype) {
  if (!t.defined()) {
    return absl::InvalidArgumentError(
        absl::StrCat("segment field ", field, " is missing"));
  }
  if (t.sizes() != at::IntArrayRef(shape)) {
    return absl::InvalidArgumentError(
        absl::StrCat("segment field ", field, " has shape ", Shape(t),
                     ", expected [", absl::StrJoin(shape, ", "), "]"));
  }
  if (t.scalar_type() != dtype) {
    return absl::InvalidArgumentError(absl::StrCat(
        "segment field ", field, " has dtype ", at::toString(t.scalar_type()),
        ", expected ", at::toString(dtype)));
  }
  // Plain loops: a segment is small, and a few tensor ops per field would
  // cost more than the data (this runs for every segment a learner takes).
  if (dtype == at::kFloat) {
    const at::Tensor dense = t.contiguous();
    const float* values = dense.data_ptr<float>();
    for (int64_t i = 0, n = dense.numel(); i < n; ++i) {
      if (!std::isfinite(values[i])) {
        return absl::InvalidArgumentError(
            absl::StrCat("segment field ", field, " holds non-finite values"));
      }
    }
  }
  return absl::OkStatus();
}

// The number of set flags, and whether any step has both.
int64_t CountSet(const at::Tensor& flags) {
  const at::Tensor dense = flags.contiguous();
  const bool* values = dense.data_ptr<bool>();
  int64_t count = 0;
  for (int64_t i = 0, n = dense.numel(); i < n; ++i) count += values[i];
  return count;
}

bool AnyBoth(const at::Tensor& a, const at::Tensor& b) {
  const at::Tensor dense_a = a.contiguous();
  const at::Tensor dense_b = b.contiguous();
  const bool* x = dense_a.data_ptr<bool>();
  const bool* y = dense_b.data_ptr<bool>();
  for (int64_t i = 0, n = dense_a.numel(); i < n; ++i) {
    if (x[i] && y[i]) return true;
  }
  return false;
}

}  // namespace

absl::Status ValidateSegment(const Segment& segment, const EnvSpec& spec,
                             int64_t max_steps) {
  const int64_t steps = segment.steps();
  if (steps < 1 || steps > max_steps) {
    return absl::InvalidArgumentError(
        absl::StrCat("segment has ", steps, " steps, expected 1..", max_steps));
  }
  const int64_t obs = spec.observation_size;
  const int64_t act = spec.discrete ? 1 : spec.action_size;
  const int64_t truncations =
      segment.truncated.defined() && segment.truncated.numel() == steps &&
              segment.truncated.scalar_type() == at::kBool
          ? CountSet(segment.truncated)
          : -1;
  for (absl::Status status : {
           Expect(segment.rewards, "rewards", {steps}, at::kFloat),
           Expect(segment.observations, "observations", {steps + 1, obs},
                  at::kFloat),
           Expect(segment.actions, "actions", {steps, act}, at::kFloat),
           Expect(segment.terminated, "terminated", {steps}, at::kBool),
           Expect(segment.truncated, "truncated", {steps}, at::kBool),
           Expect(segment.behaviour_log_probs, "behaviour_log_probs", {steps},
                  at::kFloat),
       }) {
    if (!status.ok()) return status;
  }
  if (absl::Status status =
          Expect(segment.final_observations, "final_observations",
                 {truncations, obs}, at::kFloat);
      !status.ok()) {
    return status;
  }
  if (spec.discrete) {
    const at::Tensor a = segment.actions;
    if (!(a == a.floor()).all().item<bool>() || (a < 0).any().item<bool>() ||
        (a >= static_cast<double>(spec.action_size)).any().item<bool>()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "segment field actions holds values that are not action indices "
          "in [0, ",
          spec.action_size, ")"));
    }
  }
  if (AnyBoth(segment.terminated, segment.truncated)) {
    return absl::InvalidArgumentError(
        "segment marks a step both terminated and truncated");
  }
  if (segment.episode_returns.size() != segment.episode_lengths.size()) {
    return absl::InvalidArgumentError(
        "segment lists different numbers of episode returns and lengths");
  }
  return absl::OkStatus();
}

}  // namespace vantage
