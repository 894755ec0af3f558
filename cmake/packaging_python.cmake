# SPDX-License-Identifier: BSD-3-Clause
# CPack pre-build script (cmake/packaging.cmake): the Python package's staged files move from
# lib/python3.X/dist-packages to lib/python3/dist-packages, where Debian's python3 finds them.
file(GLOB versioned LIST_DIRECTORIES true "${CPACK_TEMPORARY_INSTALL_DIRECTORY}/python/usr/lib/python3.*/dist-packages")
foreach(dir IN LISTS versioned)
  set(target "${CPACK_TEMPORARY_INSTALL_DIRECTORY}/python/usr/lib/python3/dist-packages")
  file(MAKE_DIRECTORY "${target}")
  file(GLOB entries "${dir}/*")
  foreach(entry IN LISTS entries)
    get_filename_component(name "${entry}" NAME)
    file(RENAME "${entry}" "${target}/${name}")
  endforeach()
  get_filename_component(parent "${dir}" DIRECTORY)
  file(REMOVE_RECURSE "${parent}")
endforeach()
