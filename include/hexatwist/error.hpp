// SPDX-License-Identifier: BSD-3-Clause
// The one exception type: thrown only while building a Model or parsing input, never on the
// real-time path.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>

namespace hexatwist {

/// Invalid model or input. `what()` is a single line that names the file, line, field or leg.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// An input that is readable but does not fit the rest, blamed on one of the call's parameters:
/// `parameter` is its name in snake_case ("time_offset", "register_until"), which each front end
/// turns into its own spelling (the CLI's --time-offset, Python's keyword) when it reports it.
class ParameterError : public Error {
 public:
  ParameterError(const std::string& message, std::string parameter)
      : Error(message), parameter_(std::move(parameter)) {}
  [[nodiscard]] const std::string& parameter() const noexcept { return parameter_; }

 private:
  std::string parameter_;
};

}  // namespace hexatwist
