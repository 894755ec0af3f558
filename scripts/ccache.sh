# SPDX-License-Identifier: BSD-3-Clause
# Sourced by scripts/build.sh, test.sh and fuzz.sh: compile through ccache (installed by setup.sh),
# so that a rebuild after a small change, a second build folder or a fresh clone of the same
# sources (CI) compiles only what changed. Paths are hashed relative to the clone, so clones in
# other folders share the cache. Sets `ccache_flags` for cmake (empty without ccache).
ccache_flags=()
if command -v ccache >/dev/null 2>&1 && [ "${HEXATWIST_CCACHE:-1}" != 0 ]; then
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
  ccache_flags=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
