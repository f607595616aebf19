#pragma once
/// \file errors.hpp
/// \brief Error and status types shared by every contactrom library.
///
/// User-input and I/O errors throw InputError with a one-line message that names
/// the offending value and what was expected. Numerical failure is never an
/// exception: solvers report a Status through `info()`.
#include <ostream>
#include <stdexcept>
#include <string>

namespace contactrom {

/// \brief Bad user input or unreadable/malformed file. The CLI prints `what()`
/// on one line and exits with a non-zero code.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

/// \brief Outcome of a numerical computation (Eigen-style `ComputationInfo`).
enum class Status {
  Success,         ///< converged to the requested tolerance
  NoConvergence,   ///< iteration cap reached; results are the last iterate
  NumericalIssue,  ///< factorisation failed or a NaN appeared
  InvalidInput,    ///< dimensions or values inconsistent (numerical API only)
  /// The method's own iteration converged, but the answer fails the full-order
  /// checks a user would make (e.g. a reduced answer whose contact residuals, row
  /// by row at its own pairing, exceed their tolerance: fom/contact_residuals.hpp)
  Inaccurate
};

/// \brief Lower-case name of a status, as written in JSON and CSV output.
inline const char* to_string(Status s) {
  switch (s) {
    case Status::Success: return "success";
    case Status::NoConvergence: return "no_convergence";
    case Status::NumericalIssue: return "numerical_issue";
    case Status::InvalidInput: return "invalid_input";
    case Status::Inaccurate: return "inaccurate";
  }
  return "unknown";
}

/// \brief Streams the lower-case status name (logs, test messages).
inline std::ostream& operator<<(std::ostream& out, Status s) { return out << to_string(s); }

}  // namespace contactrom
