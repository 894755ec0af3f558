// SPDX-License-Identifier: BSD-3-Clause
// Shared by the fuzz targets: the input as text, and invariant checks that stop the program (a
// crash for libFuzzer, a failed test for the replay under ctest).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "hexatwist/error.hpp"

namespace hexatwist::fuzz {

/// The fuzzer's bytes as text (any bytes, NUL included).
inline std::string_view as_text(const std::uint8_t* data, std::size_t size) noexcept {
  return size == 0 ? std::string_view() : std::string_view(reinterpret_cast<const char*>(data), size);
}

/// Aborts with `what` on stderr unless `ok`.
inline void require(bool ok, const char* what) noexcept {
  if (ok) return;
  std::fprintf(stderr, "fuzz: invariant broken: %s\n", what);
  std::abort();
}

/// The documented shape of an Error for bad input: one non-empty line, starting with `source`
/// when one is given (the name passed to the parser).
inline void require_message(const Error& e, std::string_view source = {}) noexcept {
  const std::string_view message = e.what();
  require(!message.empty(), "an Error with an empty message");
  require(message.find('\n') == std::string_view::npos, "an Error message of more than one line");
  require(message.substr(0, source.size()) == source, "an Error message that does not start with the source name");
}

}  // namespace hexatwist::fuzz
