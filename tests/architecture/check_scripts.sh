#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Every shell script of the tree parses (bash -n): scripts/test.sh runs its stages in order, so a
# quoting mistake in a late stage would otherwise surface only after the earlier ones have run.
set -uo pipefail
root=${1:?usage: check_scripts.sh SOURCE_DIR}
status=0
count=0
while IFS= read -r -d '' f; do
  count=$((count + 1))
  if ! bash -n "$f"; then
    echo "check_scripts: $f does not parse" >&2
    status=1
  fi
done < <(cd "$root" && git ls-files -z -- '*.sh' '.ci/run' 2>/dev/null | sed -z "s|^|$root/|")
if [ "$count" -eq 0 ]; then
  echo "check_scripts: no script found under $root (not a git checkout?)" >&2
  exit 1
fi
echo "check_scripts: $count scripts parse"
exit $status
