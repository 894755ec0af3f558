// SPDX-License-Identifier: BSD-3-Clause
// C API: the version, status names and descriptions (the library's, as C strings).
#include "c_api.hpp"

#include "hexatwist/version.hpp"

namespace {

using hexatwist::Status;

// The C enum mirrors hexatwist::Status value for value.
static_assert(HEXATWIST_OK == static_cast<int>(Status::Ok));
static_assert(HEXATWIST_NON_FINITE_INPUT == static_cast<int>(Status::NonFiniteInput));
static_assert(HEXATWIST_STROKE_BELOW_MIN == static_cast<int>(Status::StrokeBelowMin));
static_assert(HEXATWIST_STROKE_ABOVE_MAX == static_cast<int>(Status::StrokeAboveMax));
static_assert(HEXATWIST_BEND_BASE == static_cast<int>(Status::BendBase));
static_assert(HEXATWIST_BEND_PLATFORM == static_cast<int>(Status::BendPlatform));
static_assert(HEXATWIST_SINGULAR_BASE == static_cast<int>(Status::SingularBase));
static_assert(HEXATWIST_SINGULAR_PLATFORM == static_cast<int>(Status::SingularPlatform));
static_assert(HEXATWIST_NO_CONVERGENCE == static_cast<int>(Status::NoConvergence));
static_assert(HEXATWIST_SINGULAR_JACOBIAN == static_cast<int>(Status::SingularJacobian));
static_assert(HEXATWIST_PLATFORM_SINGULARITY == static_cast<int>(Status::PlatformSingularity));
static_assert(HEXATWIST_ASSEMBLY_MODE_CHANGED == static_cast<int>(Status::AssemblyModeChanged));

// The library's strings are literals (NUL-terminated string_views).
const char* c_str(std::string_view s) noexcept { return s.data(); }

}  // namespace

extern "C" {

const char* hexatwist_version(void) { return HEXATWIST_VERSION_STRING; }

const char* hexatwist_status_name(hexatwist_status status) {
  if (status == HEXATWIST_INVALID_ARGUMENT) return "invalid_argument";
  return c_str(hexatwist::to_string(static_cast<Status>(status)));
}

const char* hexatwist_status_describe(hexatwist_status status) {
  if (status == HEXATWIST_INVALID_ARGUMENT)
    return "a null pointer, an unknown enum value or an option outside its documented range was passed";
  return c_str(hexatwist::describe(static_cast<Status>(status)));
}

int hexatwist_status_is_limit(hexatwist_status status) {
  return status != HEXATWIST_INVALID_ARGUMENT && hexatwist::is_limit(static_cast<Status>(status)) ? 1 : 0;
}

}  // extern "C"
