"""Batch evaluations, simulation sweeps and design studies over a dask.distributed cluster, or local threads.

Batches (:func:`map_batch`) are cut into chunks of a fixed number of rows, a multiple of ``hexatwist.BLOCK``,
that do not depend on the cluster: each chunk runs the same library code as a local call on the same rows, and
forward kinematics warm-starts on BLOCK boundaries only, so the concatenated result is identical, bit for bit,
to the local run. Keyword arrays with one row per input row (``guess=`` of shape (N, 6)) are cut with it.

The design studies (``hexatwist.tolerance``, ``workspace_volume`` and ``workspace_map`` with ``client=``)
send the workers only what defines the work (the model or configuration, the settings, a range of sample
indices): the samples are generated and evaluated there, and only their summaries come back. Sample k depends
on (seed, k) alone, so the result equals the local run bit for bit whatever the workers and the chunks.

On a worker, hexatwist's threads follow the worker's thread count (``--nthreads``).

Pointing it at a cluster::

    # on the scheduler host                 # on each worker host (hexatwist importable there)
    dask scheduler --port 8786              dask worker tcp://scheduler-host:8786 --nthreads 1 --nworkers 2

    from dask.distributed import Client
    client = Client("tcp://scheduler-host:8786")
    r = hexatwist.map_batch("commands", model, poses, client=client)
    t = hexatwist.tolerance(model, platforms=10_000, random=10_000, client=client)

``python3 -m hexatwist.cluster`` is the command line's door to a cluster (``hexatwist tolerance
--scheduler``).
"""
from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

_BATCH = ("inverse_kinematics", "twist", "commands", "forward")


def _hexatwist():
    import hexatwist

    hexatwist._follow_worker()
    return hexatwist


def _function(name):
    import hexatwist

    if name not in _BATCH:
        raise hexatwist.InputError(f"map_batch: unknown function '{name}'; expected one of {', '.join(_BATCH)}")
    return getattr(hexatwist, name)


def _run_chunk(name, model, rows, kwargs, row_kwargs):
    _hexatwist()
    return dict(_function(name)(model, rows, **kwargs, **row_kwargs))


def _concatenate(parts):
    import hexatwist

    out = hexatwist.Result()
    for key in parts[0]:
        out[key] = np.concatenate([p[key] for p in parts], axis=0)
    return out


def _per_row(value, n):
    """True for a keyword array with one row per input row (cut with the rows), not one value for all."""
    if not isinstance(value, np.ndarray) or value.ndim == 0 or value.shape[0] != n:
        return False
    return not (value.ndim == 1 and value.shape[0] == 6)  # a (6,) array is one pose for every row


def map_batch(function: str, model, array, client=None, chunk: int | None = None, **kwargs):
    """Evaluates a batch function ("inverse_kinematics", "twist", "commands" or "forward") over an
    (N, 6) float64 array, in chunks of ``chunk`` rows (default 64 * BLOCK; rounded up to a multiple of
    BLOCK) on the workers of ``client`` (a dask.distributed.Client), or locally when ``client`` is None
    (one call: the library's own threads). ``kwargs`` go to the function (strategy=, kind=, guess=, ...);
    an array with one row per input row (``guess=`` (N, 6)) is cut into the same chunks, each sent with
    its own. Returns the same Result as the local call, bit for bit."""
    import hexatwist

    fn = _function(function)
    rows = np.asarray(array)
    if rows.dtype != np.float64:
        raise hexatwist.DTypeError(f"array: expected dtype float64, got {rows.dtype}")
    if rows.ndim != 2 or rows.shape[1] != 6:
        raise hexatwist.InputError(f"array: expected shape (N, 6), got {rows.shape}")
    if chunk is not None and (isinstance(chunk, bool) or not isinstance(chunk, (int, np.integer)) or chunk < 1):
        raise hexatwist.InputError(f"chunk: expected a whole number of rows >= 1, got {chunk!r}")
    if client is None:
        return fn(model, rows, **kwargs)
    kwargs = {k: (np.asarray(v) if isinstance(v, (list, tuple)) else v) for k, v in kwargs.items()}
    per_row = {k: v for k, v in kwargs.items() if _per_row(v, len(rows))}
    common = {k: v for k, v in kwargs.items() if k not in per_row}
    block = hexatwist.BLOCK
    chunk = 64 * block if chunk is None else max(1, -(-int(chunk) // block)) * block
    starts = list(range(0, len(rows), chunk)) or [0]
    model_future = client.scatter(model, broadcast=True)
    futures = []
    for i in starts:
        piece = client.scatter(np.ascontiguousarray(rows[i:i + chunk]))
        row_kwargs = {k: client.scatter(np.ascontiguousarray(v[i:i + chunk])) for k, v in per_row.items()}
        futures.append(client.submit(_run_chunk, function, model_future, piece, common, row_kwargs, pure=False))
    return _concatenate(client.gather(futures))


def _simulate(kwargs):
    return _hexatwist().simulate(**kwargs)


def map_simulations(runs, client=None, max_workers: int | None = None):
    """Runs :func:`hexatwist.simulate` once per item of ``runs`` (dicts of its keyword arguments:
    config as YAML text, test or poses, strategy, ...) on the workers of ``client``, or on local threads
    (``max_workers``, default the CPU count; simulate releases the GIL) when ``client`` is None.
    Returns the list of Results in the order of ``runs``."""
    runs = [dict(r) for r in runs]
    if client is None:
        with ThreadPoolExecutor(max_workers=max_workers or os.cpu_count() or 1) as pool:
            return list(pool.map(_simulate, runs))
    return client.gather([client.submit(_simulate, r, pure=False) for r in runs])


# ---- design studies on a cluster ---------------------------------------------------------------


def _ranges(total: int, chunk: int):
    return [(first, min(chunk, total - first)) for first in range(0, total, chunk)]


def _volume_task(model, grid, step, tolerance, strategy, first, count):
    return _hexatwist()._core._volume_cells(model, grid, step, tolerance, strategy, first, count)


def workspace_volume_on(client, model, orientation, cell, refine, step, tolerance, strategy, chunk):
    """hexatwist.workspace_volume on the workers: the grid (bounds arithmetic) here, its cells there,
    ``chunk`` cells a task (default: the grid in about 32 tasks of whole rows), their sums here."""
    core = _hexatwist()._core
    grid = core._volume_grid(model, orientation, cell, refine, step, tolerance, strategy)
    n = grid["cells"]
    chunk = int(chunk) if chunk else grid["nx"] * max(1, math.ceil(grid["ny"] / 32))
    model_future = client.scatter(model, broadcast=True)
    futures = [client.submit(_volume_task, model_future, grid, step, tolerance, strategy, first, count, pure=False)
               for first, count in _ranges(n, max(1, chunk))]
    parts = client.gather(futures)
    fine = np.concatenate([p[0] for p in parts])
    coarse = np.concatenate([p[1] for p in parts])
    return core._volume_from_cells(grid, fine, coarse, sum(int(p[2]) for p in parts))


def _map_grid_task(model, orientation, plane, offset, spacing, step, tolerance, strategy):
    return _hexatwist()._core._map_grid(model, orientation, plane, offset, spacing, step, tolerance, strategy)


def _map_task(model, orientation, grid, strategy, first, count):
    return _hexatwist()._core._workspace_map_rows(model, orientation, grid, strategy, first, count)


def workspace_map_on(client, model, orientation, plane, offset, spacing, grid, step, tolerance, strategy, chunk):
    """hexatwist.workspace_map on the workers: the grid (a slice search) in one task, then ``chunk``
    rows a task (default: about 32 tasks); the rows come back and are stacked in order."""
    import hexatwist

    model_future = client.scatter(model, broadcast=True)
    if grid is None:
        grid = client.submit(_map_grid_task, model_future, tuple(orientation), plane, offset, spacing, step, tolerance,
                             strategy, pure=False).result()
    chunk = int(chunk) if chunk else max(1, math.ceil(grid["nv"] / 32))
    futures = [client.submit(_map_task, model_future, tuple(orientation), grid, strategy, first, count, pure=False)
               for first, count in _ranges(grid["nv"], chunk)]
    r = _concatenate(client.gather(futures))
    return hexatwist._map_result(r, grid)


def _tolerance_task(config, poses, workspace, sigmas, seed, first, count, calibration, linear_worst, tracker):
    hexatwist = _hexatwist()
    return hexatwist._core._tolerance_chunk(config, poses, workspace, sigmas, seed, first, count, calibration,
                                            linear_worst, hexatwist.get_num_threads(), tracker)


def _linear_task(config, poses, workspace, sigmas, calibration, tracker, seed):
    hexatwist = _hexatwist()
    return hexatwist._core._tolerance_linear(config, poses, workspace, sigmas, hexatwist.get_num_threads(),
                                             calibration, tracker, seed)


_HISTOGRAMS = ("histogram_point", "histogram_position", "histogram_orientation")


def merge_tolerance_chunks(parts):
    """One study from its chunks (in platform order): the per-platform arrays concatenated, the
    histograms added (integer counts)."""
    parts = sorted(parts, key=lambda p: p["first"])
    out = {"first": parts[0]["first"]}
    for key in parts[0]:
        if key == "first":
            continue
        if key in _HISTOGRAMS:
            out[key] = np.sum([p[key] for p in parts], axis=0, dtype=np.uint64)
        else:
            out[key] = np.concatenate([p[key] for p in parts])
    return out


def tolerance_on(client, config, poses, workspace, sigmas, seed, platforms, calibration, linear_worst, chunk,
                 linear=True, tracker=None):
    """hexatwist.tolerance on the workers: ``chunk`` platforms a task (default: about 64 tasks), each
    sampling its platforms from (seed, index) and generating the poses from ``workspace`` (``poses``,
    when given, are scattered once), a tracker calibration's noise from (seed, index) too; one task for
    the covariance answer (``linear``). Returns (chunk, linear or None)."""
    chunk = int(chunk) if chunk else max(1, math.ceil(platforms / 64))
    config_future = client.scatter(config, broadcast=True) if config is not None else None
    poses_future = client.scatter(np.ascontiguousarray(poses, dtype=np.float64), broadcast=True) \
        if poses is not None else None
    linear = client.submit(_linear_task, config_future, poses_future, workspace, sigmas, calibration, tracker, seed,
                           pure=False) if linear else None
    futures = [client.submit(_tolerance_task, config_future, poses_future, workspace, sigmas, seed, first, count,
                             calibration, linear_worst, tracker, pure=False)
               for first, count in _ranges(platforms, chunk)]
    return merge_tolerance_chunks(client.gather(futures)), linear.result() if linear is not None else None
