#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Runs the sample configuration seed.ini: LinuxCNC with hexatwistkins on the seed platform, the
# joints simulated, and hexatwist_display.py as the user interface (no window: it homes, makes a
# few moves and prints what LinuxCNC reports). Install the module first:
#   cmake --install build --component linuxcnc
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
modules=/usr/lib/linuxcnc/modules
if [ ! -f "$modules/hexatwistkins.so" ]; then
  echo "run.sh: $modules/hexatwistkins.so is missing; install it: cmake --install build --component linuxcnc" >&2
  exit 2
fi
if [ "$(id -u)" -eq 0 ]; then
  # rtapi_app refuses plain root: it runs as a fallback user, who needs a writable socket folder.
  fifo=$(mktemp -d)
  chmod 1777 "$fifo"
  trap 'rm -rf "$fifo"' EXIT
  export RTAPI_UID=${RTAPI_UID:-65534} RTAPI_FIFO_PATH=${RTAPI_FIFO_PATH:-$fifo/rtapi_fifo}
fi
cd "$here"
# -r: print to this terminal even without one (LinuxCNC otherwise writes to temporary logs).
linuxcnc -r seed.ini
