# SPDX-License-Identifier: BSD-3-Clause
# step(COMMAND...): runs a command of a test script (cmake -P), stopping the script with its output
# if it fails; its standard output is in `step_output` afterwards. Included by tests/install/run.cmake
# and tests/packaging/check_debs.cmake.
function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()
