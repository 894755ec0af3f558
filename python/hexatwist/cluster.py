# SPDX-License-Identifier: BSD-3-Clause
"""The command line's door to a Dask cluster (``hexatwist tolerance --scheduler``, ``hexatwist workspace
--scheduler``): ``python3 -m hexatwist.cluster`` reads one request (JSON) on standard input, runs it on the
cluster through :mod:`hexatwist.distributed` and writes the merged summaries on standard output, one array a
line ("name count v1 v2 ...", floats as exact hexadecimal), for the command line to finish the report."""
from __future__ import annotations

import json
import sys
from typing import IO, Any, Mapping

import numpy as np

from .distributed import _tolerance_on, _workspace_map_on, _workspace_volume_on


def _write_arrays(out: IO[str], prefix: str, values: Mapping[str, Any]) -> None:
    """Lines "name count v1 v2 ..." with floats as exact hexadecimal and integers in decimal."""
    for key, value in values.items():
        if isinstance(value, dict):
            _write_arrays(out, f"{prefix}{key}.", value)
            continue
        a = np.atleast_1d(np.asarray(value))
        if a.dtype.kind in "iub":
            items = " ".join(str(int(v)) for v in a.ravel())
        else:
            items = " ".join(float(v).hex() for v in a.ravel())
        out.write(f"{prefix}{key} {a.size} {items}\n")


def main(argv: list[str] | None = None) -> int:
    """Runs one request of the command line on a cluster: JSON on standard input with ``job``
    ("tolerance" or "workspace"), ``scheduler`` and the job's settings; the merged summaries on
    standard output. Exit 2 when the scheduler cannot be reached, 3 when the job fails (the reason on
    standard error)."""
    request = json.load(sys.stdin)
    import hexatwist
    from dask.distributed import Client

    try:
        client = Client(request["scheduler"], timeout=request.get("timeout", 30))
    except (OSError, TimeoutError) as e:
        print(f"cannot reach the Dask scheduler {request['scheduler']}: {e}", file=sys.stderr)
        return 2
    out = sys.stdout
    with client:
        workers = len(client.scheduler_info()["workers"])
        out.write(f"workers 1 {workers}\n")
        config = request.get("config")
        if request["job"] == "tolerance":
            poses = np.asarray(request["poses"], dtype=np.float64) if "poses" in request else None
            chunk, _ = _tolerance_on(client, config, poses, request["workspace"], request["sigmas"], request["seed"],
                                    request["platforms"], request.get("calibration", "none"), True,
                                    request.get("chunk"), linear=False, tracker=request.get("tracker"))
            _write_arrays(out, "", chunk)
        elif request["job"] == "workspace":
            model = hexatwist.Rig(config).model
            volume = _workspace_volume_on(client, model, request["orientation"], request["cell"], request["refine"],
                                         request["step"], request["tolerance"], "compensated", request.get("chunk"))
            _write_arrays(out, "volume.", {k: volume[k] for k in ("volume", "coarse_volume", "error", "columns")})
            grid = request.get("map_grid")
            rows, _ = _workspace_map_on(client, model, request["orientation"], None, None, None, grid, None, None,
                                       "compensated", request.get("map_chunk"))
            _write_arrays(out, "map.", rows)  # the library's values: legs as 0-based indices
        else:
            print(f"unknown job '{request['job']}'", file=sys.stderr)
            return 3
    return 0


if __name__ == "__main__":
    sys.exit(main())
