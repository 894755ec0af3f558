# SPDX-License-Identifier: BSD-3-Clause
# Builds the Debian packages of the build tree (cmake/packaging.cmake) with cpack and checks them as
# a user installing them would: each package's name, section and dependencies, then its files
# unpacked into a scratch root and used from there: the tool runs `ik` on the packaged seed
# configuration, Debian's python3 imports the package, the LinuxCNC module and the headers are in
# place. Run by ctest (tests/CMakeLists.txt) with BUILD_DIR, WORK_DIR and PYTHON.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")
include(${CMAKE_CURRENT_LIST_DIR}/../install/step.cmake)

step(cpack -G DEB --config "${BUILD_DIR}/CPackConfig.cmake" -B "${WORK_DIR}/debs")
file(GLOB debs "${WORK_DIR}/debs/*.deb")
set(expected hexatwist libhexatwist-dev python3-hexatwist hexatwist-linuxcnc)
foreach(package IN LISTS expected)
  set(found "")
  foreach(deb IN LISTS debs)
    execute_process(COMMAND dpkg-deb -f "${deb}" Package OUTPUT_VARIABLE name OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(name STREQUAL package)
      set(found "${deb}")
    endif()
  endforeach()
  if(NOT found)
    message(FATAL_ERROR "no package ${package} among: ${debs}")
  endif()
  step(dpkg-deb -f "${found}" Package Version Architecture Depends Section Description)
  message(STATUS "${package}:\n${step_output}")
  set(fields_${package} "${step_output}")
  step(dpkg-deb -x "${found}" "${WORK_DIR}/root")
endforeach()

# The dependencies a user's apt needs: shared libraries found by dpkg-shlibdeps, and the others.
foreach(pair "hexatwist|libyaml-cpp" "hexatwist|libfmt" "hexatwist|libc6" "libhexatwist-dev|libeigen3-dev"
             "python3-hexatwist|python3-numpy" "hexatwist-linuxcnc|linuxcnc-uspace")
  string(REPLACE "|" ";" pair "${pair}")
  list(GET pair 0 package)
  list(GET pair 1 dependency)
  if(NOT fields_${package} MATCHES "Depends:[^\n]*${dependency}")
    message(FATAL_ERROR "${package} does not depend on ${dependency}:\n${fields_${package}}")
  endif()
endforeach()

set(root "${WORK_DIR}/root")
foreach(file usr/bin/hexatwist usr/share/hexatwist/configs/seed.yaml usr/share/doc/hexatwist/copyright
             usr/include/hexatwist/hexatwist.hpp usr/include/hexatwist/c/hexatwist.h
             usr/lib/cmake/hexatwist/hexatwistConfig.cmake usr/lib/python3/dist-packages/hexatwist/__init__.py
             usr/lib/linuxcnc/modules/hexatwistkins.so)
  if(NOT EXISTS "${root}/${file}")
    file(GLOB_RECURSE all RELATIVE "${root}" "${root}/*")
    message(FATAL_ERROR "the packages do not install /${file}; they hold:\n${all}")
  endif()
endforeach()

step("${root}/usr/bin/hexatwist" ik --config "${root}/usr/share/hexatwist/configs/seed.yaml" --pose 0,0,0.1,0,0,10 --json)
if(NOT step_output MATCHES "\"status\": \"ok\"")
  message(FATAL_ERROR "the packaged hexatwist ik did not report ok:\n${step_output}")
endif()
file(WRITE "${WORK_DIR}/use.py"
     "import hexatwist, numpy\n"
     "m = hexatwist.load_model('${root}/usr/share/hexatwist/configs/seed.yaml')\n"
     "print(hexatwist.__file__)\n"
     "print(hexatwist.commands(m, numpy.zeros((1, 6)), 'compensated'))\n")
step(${CMAKE_COMMAND} -E env "PYTHONPATH=${root}/usr/lib/python3/dist-packages" "${PYTHON}" "${WORK_DIR}/use.py")
string(FIND "${step_output}" "${root}/usr/lib/python3/dist-packages/hexatwist/__init__.py" at)
if(at EQUAL -1)
  message(FATAL_ERROR "python3 did not import the packaged hexatwist:\n${step_output}")
endif()
message(STATUS "packaged Python: ${step_output}")
