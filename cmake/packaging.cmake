# SPDX-License-Identifier: BSD-3-Clause
# Debian packages of hexatwist, one per install component (`cpack -G DEB` in the build folder;
# tests/packaging/check_debs.cmake builds and checks them):
#   hexatwist            the command-line tool, the seed configuration, the licence
#   libhexatwist-dev     the C++ and C libraries (static), their headers and CMake package
#   python3-hexatwist    the Python package
#   hexatwist-linuxcnc   the LinuxCNC kinematics module (into LinuxCNC's own modules folder)
# Dependencies on shared libraries are found by dpkg-shlibdeps; the others are listed here.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME hexatwist)
set(CPACK_PACKAGE_VENDOR "hexatwist developers")
set(CPACK_PACKAGE_CONTACT "hexatwist developers <hexatwist@localhost>")
# The code is built for one x86-64 level (HEXATWIST_ARCH; the default is this computer's): a package
# runs on CPUs of that level or above, and says which. Build packages for the machines' lowest level:
# cmake -DHEXATWIST_ARCH=x86-64-v2 (or v3).
if(HEXATWIST_ARCH)
  set(hexatwist_package_level " (${HEXATWIST_ARCH} CPUs)")
endif()
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "twist-aware kinematics of lead-screw Stewart platforms${hexatwist_package_level}")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "https://github.com/hexatwist/hexatwist")
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME hexatwist)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_RECOMMENDS gnuplot-nox)
set(CPACK_COMPONENT_RUNTIME_DESCRIPTION "The hexatwist command: motor commands that compensate the screw twist of U-joint legs,\nforward kinematics, the paper's study, motor sizing, tracker measurement and identification, a real-time stream.")
set(CPACK_DEBIAN_DEV_PACKAGE_NAME libhexatwist-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "libeigen3-dev, libyaml-cpp-dev, libfmt-dev, libceres-dev")
set(CPACK_COMPONENT_DEV_DESCRIPTION "The C++ and C libraries (static), their headers and the CMake package (find_package(hexatwist)).")
if(HEXATWIST_PYTHON)
  list(APPEND CPACK_COMPONENTS_ALL python)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-hexatwist)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "python3-numpy")
  set(CPACK_COMPONENT_PYTHON_DESCRIPTION "The Python package: numpy in and out; tolerance studies on Dask with python3-distributed.")
  # Debian's python3 looks in /usr/lib/python3/dist-packages: the package goes there, whatever
  # folder this build's own install uses (cmake/packaging_python.cmake moves it).
  set(CPACK_PRE_BUILD_SCRIPTS ${PROJECT_SOURCE_DIR}/cmake/packaging_python.cmake)
endif()
if(TARGET hexatwistkins)
  list(APPEND CPACK_COMPONENTS_ALL linuxcnc)
  set(CPACK_DEBIAN_LINUXCNC_PACKAGE_NAME hexatwist-linuxcnc)
  set(CPACK_DEBIAN_LINUXCNC_PACKAGE_DEPENDS "linuxcnc-uspace")
  set(CPACK_COMPONENT_LINUXCNC_DESCRIPTION "The LinuxCNC kinematics module hexatwistkins.so: the compensated kinematics in LinuxCNC.")
endif()
include(CPack)
