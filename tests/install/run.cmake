# SPDX-License-Identifier: BSD-3-Clause
# Installs the build tree into a scratch prefix, then configures, builds and runs an outside
# project that uses find_package(hexatwist). Run by ctest (tests/CMakeLists.txt).
file(REMOVE_RECURSE "${WORK_DIR}")
include(${CMAKE_CURRENT_LIST_DIR}/step.cmake)
# The components runtime (the tool) and dev (the libraries, headers and package files). The
# LinuxCNC module (component linuxcnc) goes to LinuxCNC's own modules folder, outside any prefix.
step(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix" --component runtime)
step(${CMAKE_COMMAND} --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix" --component dev)
step(${CMAKE_COMMAND} -S "${SOURCE_DIR}" -B "${WORK_DIR}/build" -G "${GENERATOR}" -DCMAKE_BUILD_TYPE=Release
     "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix")
step(${CMAKE_COMMAND} --build "${WORK_DIR}/build")
step("${WORK_DIR}/build/consumer")
message(STATUS "consumer: ${step_output}")
step("${WORK_DIR}/build/consumer_c")
message(STATUS "consumer_c: ${step_output}")
step("${WORK_DIR}/prefix/bin/hexatwist" ik --json)
if(NOT step_output MATCHES "\"status\": \"ok\"")
  message(FATAL_ERROR "installed hexatwist ik did not report ok:\n${step_output}")
endif()
