// Error tiers.  InputError: the user's scene or mesh is wrong (file, line, key, what is valid).
// NumericalFailure: the run became unstable (which element, which step, what to try).
// IoError: an output or checkpoint file could not be written (disk full, quota, permissions).
// Each carries a complete one-paragraph message; the driver prints it and exits non-zero with
// the tier's code (README: 2 input, 3 numerical, 4 I/O).
#pragma once

#include <stdexcept>
#include <string>

namespace fdem {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class NumericalFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class IoError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Always-on check for internal invariants (a failure here is a bug in fdem, not user error).
[[noreturn]] void internal_error(const char* file, int line, const std::string& what);
#define FDEM_VERIFY(cond, msg)                                    \
  do {                                                            \
    if (!(cond)) ::fdem::internal_error(__FILE__, __LINE__, msg); \
  } while (0)

}  // namespace fdem
