#ifndef VANTAGE_ACTOR_ENVS_PYTHON_PYTHON_OBSERVATIONS_H_
#define VANTAGE_ACTOR_ENVS_PYTHON_PYTHON_OBSERVATIONS_H_

// What a Python environment's observations look like, from its observation
// space: one box, or a Dict's or Tuple's box entries (an image entry is a
// uint8 box of height x width x channels; any other box is a vector), and
// the check and copy of each observation into the flat row vantage keeps
// (entries side by side in the space's order, images channels first).
// Every call needs the GIL held.

#include <pybind11/pybind11.h>

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "absl/types/span.h"
#include "common/env/environment.h"

namespace vantage {

class PythonObservations {
 public:
  // From the bridge's observation_entries(space); fills `spec`'s
  // observation fields. A Dict holding an "action_mask" key says so in
  // `mask_key` (the key is the action mask, not an entry); a Dict of
  // "observation" and "action_mask" alone keeps the one observation's
  // layout (PettingZoo's convention).
  static absl::StatusOr<PythonObservations> Describe(
      const pybind11::tuple& entries, EnvSpec& spec, bool& mask_key);

  // Checks `value` (a call's observation: an array, or a dict or tuple of
  // them) against the space and writes it into `out`; errors name the env,
  // the call and the entry.
  absl::Status Write(pybind11::handle value, const char* call,
                     absl::Span<double> out) const;

 private:
  struct Entry {
    std::string key;             // empty for a single observation
    std::vector<int64_t> shape;  // as the environment gives it
    char kind = 'f';             // numpy's kind of the space's dtype
    bool image = false;          // uint8 height x width x channels
    int64_t offset = 0;          // in the row
    int64_t size = 0;
    int64_t high = 0;  // an image's top value
  };

  absl::Status AddEntry(const std::string& key, const pybind11::tuple& box);
  absl::Status WriteEntry(const Entry& entry, pybind11::handle value,
                          const char* call, absl::Span<double> out) const;
  // `entry`'s value in a dict or tuple observation, or null (an error) if
  // `value` has none.
  absl::StatusOr<pybind11::object> Lookup(const Entry& entry,
                                          pybind11::handle value,
                                          const char* call) const;

  std::string name_;       // the env's, for messages
  std::string container_;  // "single", "dict" or "tuple"
  std::vector<Entry> entries_;
};

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_PYTHON_PYTHON_OBSERVATIONS_H_
