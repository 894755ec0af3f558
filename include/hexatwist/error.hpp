// The one exception type: thrown only while building a Model or parsing input, never on the
// real-time path.
#pragma once

#include <stdexcept>
#include <string>

namespace hexatwist {

/// Invalid model or input. `what()` is a single line that names the file, line, field or leg.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace hexatwist
