#ifndef VANTAGE_ACTOR_ENVS_PYTHON_PYTHON_RUNTIME_H_
#define VANTAGE_ACTOR_ENVS_PYTHON_PYTHON_RUNTIME_H_

// The one CPython interpreter a process embeds for Python environments,
// started on first use (PYTHONPATH honoured, the working directory first on
// sys.path, Python's own signal handlers not installed) and never stopped.
// Between calls the interpreter does not hold the GIL: code that calls into
// Python takes it (pybind11::gil_scoped_acquire) for as long as Python runs.
// Only python_env.cc and the tests include this header.

#include <pybind11/pybind11.h>

#include <string>

#include "absl/status/status.h"

namespace vantage {

// Starts the interpreter if this is the first call; the GIL is released on
// return. Thread-safe.
void EnsurePythonInterpreter();

// vantage's helper module inside the interpreter (spaces, factories,
// tracebacks); call with the GIL held.
pybind11::module_& PythonBridge();

// The pending Python exception `error` as one line for the caller:
// "`what`: ExceptionType: message (file.py:12 in step)", its full
// traceback written to stderr. Call with the GIL held.
absl::Status PythonError(pybind11::error_already_set& error,
                         const std::string& what);

}  // namespace vantage

#endif  // VANTAGE_ACTOR_ENVS_PYTHON_PYTHON_RUNTIME_H_
