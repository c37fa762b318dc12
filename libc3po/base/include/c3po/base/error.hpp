#pragma once
// Errors. The library throws InputError for bad user input (a file, a field, a
// value) with a one-line message that names the file and the problem; the CLI
// prints it and exits with status 2. A broken programming contract throws
// std::invalid_argument / std::logic_error. Degenerate data is an outcome, not
// an exception (see RegistrationStatus, Certificate).
#include <stdexcept>
#include <string>

namespace c3po {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
  // "file: message"
  InputError(const std::string& file, const std::string& message)
      : std::runtime_error(file + ": " + message) {}
};

// Raised when the user interrupts long work (SIGINT/SIGTERM) between steps.
class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

}  // namespace c3po
