#ifndef VANTAGE_ACTOR_ENVS_PYTHON_PYTHON_ENV_H_
#define VANTAGE_ACTOR_ENVS_PYTHON_PYTHON_ENV_H_

// Environments written in Python with Gymnasium's API, stepped through the
// process's embedded interpreter (see docs/environments.md, "Your own
// environment in Python").

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "common/env/environment.h"

namespace vantage {

// Whether `name` names a Python environment: "python:MODULE:CALLABLE"
// (MODULE importable or a path to a .py file) or "gym:ID" (gymnasium.make).
bool IsPythonEnvName(absl::string_view name);

// Calls the factory `name` names with the keyword arguments of
// `kwargs_json` (a JSON object; empty: none) and wraps what it returns.
// Errors name the env and the call; a factory that cannot be imported or
// raises is InvalidArgument with the exception's last line.
absl::StatusOr<std::unique_ptr<Environment>> MakePythonEnv(
    absl::string_view name, const std::string& kwargs_json);

// Steps per second of the same environment stepped `steps` times by a
// plain Python loop with the fixed `action` (as the bridge takes it: an
// index, or the box's values), resetting as episodes end: what `vantage
// bench env` holds the bridge's rate against.
absl::StatusOr<double> PlainPythonStepsPerSecond(
    absl::string_view name, const std::string& kwargs_json,
    const std::vector<double>& action, int64_t steps);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_PYTHON_PYTHON_ENV_H_
