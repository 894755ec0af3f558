// SPDX-License-Identifier: BSD-3-Clause
// The library's version: the one place it is written. CMake reads these three numbers for
// project(VERSION) (the packages, the CMake package), the CLI prints them with --version, the C API
// returns them from hexatwist_version() and Python has them as hexatwist.__version__.
#pragma once

#include <string_view>

#define HEXATWIST_VERSION_MAJOR 0
#define HEXATWIST_VERSION_MINOR 1
#define HEXATWIST_VERSION_PATCH 0

#define HEXATWIST_VERSION_TEXT_(x) #x
#define HEXATWIST_VERSION_TEXT(x) HEXATWIST_VERSION_TEXT_(x)
/// "major.minor.patch", a string literal (for C and the preprocessor).
#define HEXATWIST_VERSION_STRING                  \
  HEXATWIST_VERSION_TEXT(HEXATWIST_VERSION_MAJOR) \
  "." HEXATWIST_VERSION_TEXT(HEXATWIST_VERSION_MINOR) "." HEXATWIST_VERSION_TEXT(HEXATWIST_VERSION_PATCH)

namespace hexatwist {

/// The version of the headers being compiled, "major.minor.patch".
inline constexpr std::string_view kVersion = HEXATWIST_VERSION_STRING;

}  // namespace hexatwist
