#include "actor/envs/python/python_observations.h"

#include <pybind11/numpy.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace py = pybind11;

namespace vantage {
namespace {

std::string ShapeText(const std::vector<int64_t>& shape) {
  return shape.size() == 1 ? absl::StrCat("(", shape[0], ",)")
                           : absl::StrCat("(", absl::StrJoin(shape, ", "), ")");
}

// "the observation" or "observation['camera']", for messages.
std::string What(const std::string& key) {
  return key.empty() ? "an observation"
                     : absl::StrCat("an observation['", key, "']");
}

// An image as Gymnasium lays it out (height x width x channels) into `out`
// channels first.
void WriteImage(const py::array& array, const std::vector<int64_t>& shape,
                absl::Span<double> out) {
  auto pixels = py::array_t<uint8_t, py::array::c_style>::ensure(array);
  const int64_t h = shape[0], w = shape[1], c = shape[2];
  const uint8_t* in = pixels.data();
  for (int64_t y = 0; y < h; ++y) {
    for (int64_t x = 0; x < w; ++x) {
      for (int64_t k = 0; k < c; ++k) {
        out[(k * h + y) * w + x] = in[(y * w + x) * c + k];
      }
    }
  }
}

// A numeric array into `out`: float32 and float64 (nearly every env) read
// where they lie, other dtypes and strided arrays through one converted
// copy.
void WriteValues(const py::array& array, absl::Span<double> out) {
  const bool packed = array.flags() & py::array::c_style;
  if (packed && array.dtype().is(py::dtype::of<float>())) {
    const float* in = static_cast<const float*>(array.data());
    std::copy(in, in + out.size(), out.begin());
  } else if (packed && array.dtype().is(py::dtype::of<double>())) {
    std::memcpy(out.data(), array.data(), out.size() * sizeof(double));
  } else {
    auto values =
        py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(
            array);
    std::memcpy(out.data(), values.data(), out.size() * sizeof(double));
  }
}

}  // namespace

absl::StatusOr<PythonObservations> PythonObservations::Describe(
    const py::tuple& entries, EnvSpec& spec, bool& mask_key) {
  PythonObservations observations;
  observations.name_ = spec.name;
  observations.container_ = entries[0].cast<std::string>();
  mask_key = entries[2].cast<bool>();
  for (py::handle item : entries[1].cast<py::list>()) {
    py::tuple entry = item.cast<py::tuple>();
    if (absl::Status status = observations.AddEntry(
            entry[0].cast<std::string>(), entry[1].cast<py::tuple>());
        !status.ok()) {
      return status;
    }
  }
  const std::vector<Entry>& all = observations.entries_;
  const bool keyed =
      observations.container_ != "single" &&
      !(mask_key && all.size() == 1 && all[0].key == "observation");
  spec.observation_size = all.back().offset + all.back().size;
  for (const Entry& entry : all) {
    const std::vector<int64_t> shape =
        entry.image ? std::vector<int64_t>{entry.shape[2], entry.shape[0],
                                           entry.shape[1]}
                    : std::vector<int64_t>{};
    if (!keyed) {
      spec.observation_shape = shape;
      spec.observation_high = entry.image ? entry.high : 0;
      continue;
    }
    spec.observation_keys.push_back(
        {entry.key, entry.size, shape, entry.image ? entry.high : 0});
  }
  return observations;
}

absl::Status PythonObservations::AddEntry(const std::string& key,
                                          const py::tuple& box) {
  Entry entry;
  entry.key = key;
  entry.shape = box[2].cast<std::vector<int64_t>>();
  const std::string dtype = box[3].cast<std::string>();
  entry.kind = dtype.size() > 1 ? dtype[1] : '?';
  const std::string what =
      key.empty() ? "observations" : absl::StrCat("observation['", key, "']");
  if (std::string("fiub").find(entry.kind) == std::string::npos) {
    return absl::InvalidArgumentError(absl::StrCat(
        name_, ": ", what, " of dtype ", dtype,
        " are not numbers; vantage takes float, int, uint or bool boxes"));
  }
  entry.size = 1;
  for (int64_t d : entry.shape) {
    if (d < 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(name_, ": the shape ", ShapeText(entry.shape), " of ",
                       what, " has an empty dimension"));
    }
    entry.size *= d;
  }
  entry.image = dtype == "|u1" && entry.shape.size() == 3;
  if (entry.image) {
    const std::vector<double> high = box[5].cast<std::vector<double>>();
    const double top = *std::max_element(high.begin(), high.end());
    entry.high = static_cast<int64_t>(std::clamp(top, 1.0, 255.0));
  }
  entry.offset =
      entries_.empty() ? 0 : entries_.back().offset + entries_.back().size;
  entries_.push_back(std::move(entry));
  return absl::OkStatus();
}

absl::Status PythonObservations::Write(py::handle value, const char* call,
                                       absl::Span<double> out) const {
  if (container_ == "single") {
    return WriteEntry(entries_[0], value, call, out);
  }
  for (const Entry& entry : entries_) {
    absl::StatusOr<py::object> part = Lookup(entry, value, call);
    if (!part.ok()) return part.status();
    if (absl::Status status = WriteEntry(entry, *part, call,
                                         out.subspan(entry.offset, entry.size));
        !status.ok()) {
      return status;
    }
  }
  return absl::OkStatus();
}

absl::StatusOr<py::object> PythonObservations::Lookup(const Entry& entry,
                                                      py::handle value,
                                                      const char* call) const {
  if (container_ == "dict" && py::isinstance<py::dict>(value)) {
    py::dict parts = py::reinterpret_borrow<py::dict>(value);
    if (parts.contains(entry.key)) return parts[entry.key.c_str()];
  }
  if (container_ == "tuple" && py::isinstance<py::sequence>(value)) {
    py::sequence parts = py::reinterpret_borrow<py::sequence>(value);
    const size_t index = std::stoul(entry.key);
    if (index < py::len(parts)) return parts[index];
  }
  return absl::InvalidArgumentError(absl::StrCat(
      name_, ": ", call, " returned an observation without its ", container_,
      " entry '", entry.key, "', which its space has"));
}

absl::Status PythonObservations::WriteEntry(const Entry& entry,
                                            py::handle value, const char* call,
                                            absl::Span<double> out) const {
  py::array array = py::array::ensure(value);
  if (!array) {
    return absl::InvalidArgumentError(
        absl::StrCat(name_, ": ", call, " returned ", What(entry.key),
                     " that is not an array"));
  }
  std::vector<int64_t> shape(array.shape(), array.shape() + array.ndim());
  if (shape != entry.shape) {
    return absl::InvalidArgumentError(
        absl::StrCat(name_, ": ", call, " returned ", What(entry.key),
                     " of shape ", ShapeText(shape),
                     "; the observation space's is ", ShapeText(entry.shape)));
  }
  const bool fits = entry.image ? array.dtype().is(py::dtype::of<uint8_t>())
                                : array.dtype().kind() == entry.kind;
  if (!fits) {
    return absl::InvalidArgumentError(absl::StrCat(
        name_, ": ", call, " returned ", What(entry.key), " of dtype ",
        py::str(array.dtype()).cast<std::string>(),
        "; the observation space's is ", entry.image ? "uint8" : "of kind ",
        entry.image ? "" : std::string(1, entry.kind)));
  }
  if (entry.image) {
    WriteImage(array, shape, out);
    return absl::OkStatus();
  }
  WriteValues(array, out);
  for (size_t i = 0; i < out.size(); ++i) {
    if (!std::isfinite(out[i])) {
      return absl::InvalidArgumentError(absl::StrCat(
          name_, ": ", call, " returned ", What(entry.key), " whose value ", i,
          " is ", out[i], ", which is not finite"));
    }
  }
  return absl::OkStatus();
}

}  // namespace vantage
