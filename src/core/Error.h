#pragma once
// Errors Plano reports instead of aborting. Each kind maps to one exit code of the
// `plano` tool, so a script can tell bad input from a numerical or device failure.
#include <stdexcept>
#include <string>

namespace plano {

enum class ErrorKind {
  Usage = 2,      ///< The caller asked for something that makes no sense (bad option, bad path).
  BadInput = 3,   ///< Input data is malformed: mesh file, constraint file, NaN, non-manifold, ...
  Numerical = 4,  ///< A solver failed: infeasible, iteration cap, NaN mid-iteration, singular fit.
  Device = 5,     ///< The compute device failed: no Vulkan, missing feature, out of memory, lost.
};

/// Exit code of the `plano` tool for an error kind.
inline int exitCode(ErrorKind kind) { return static_cast<int>(kind); }

inline const char* toString(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::Usage: return "usage error";
    case ErrorKind::BadInput: return "bad input";
    case ErrorKind::Numerical: return "numerical failure";
    case ErrorKind::Device: return "device failure";
  }
  return "error";
}

/// The one exception type of the library. The message names the element (file, line,
/// face, vertex) and what is wrong with it.
class Error : public std::runtime_error {
 public:
  Error(ErrorKind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  ErrorKind kind() const { return kind_; }

 private:
  ErrorKind kind_;
};

/// A result refused before it was allocated because it cannot fit in memory (core/Memory.h):
/// a numerical failure to the tool, but one that no fallback with the same matrices avoids,
/// so fallbacks rethrow it rather than trying again.
class OutOfMemory : public Error {
 public:
  explicit OutOfMemory(const std::string& message) : Error(ErrorKind::Numerical, message) {}
};

[[noreturn]] inline void throwBadInput(const std::string& message) { throw Error(ErrorKind::BadInput, message); }
[[noreturn]] inline void throwNumerical(const std::string& message) { throw Error(ErrorKind::Numerical, message); }
[[noreturn]] inline void throwDevice(const std::string& message) { throw Error(ErrorKind::Device, message); }
[[noreturn]] inline void throwUsage(const std::string& message) { throw Error(ErrorKind::Usage, message); }

}  // namespace plano
