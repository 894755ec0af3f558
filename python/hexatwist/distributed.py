# SPDX-License-Identifier: BSD-3-Clause
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

import dataclasses
import math
import os
from collections.abc import Iterable, Mapping
from concurrent.futures import ThreadPoolExecutor
from types import ModuleType
from typing import Any, Literal, TypeVar, overload

import numpy as np

from ._hexatwist import Model
from .core import ArrayLike, FloatArray, Result
from .kinematics import Commands, ForwardKinematics, InverseKinematics, LegLengths, Twist
from .simulation import Simulation

__all__ = ["map_batch", "map_simulations"]

_BATCH = ("inverse_kinematics", "twist", "commands", "forward")

R = TypeVar("R", bound=Result)


def _hexatwist() -> ModuleType:
    import hexatwist

    hexatwist.core._follow_worker()
    return hexatwist


def _function(name: str) -> Any:
    import hexatwist

    if name not in _BATCH:
        raise hexatwist.InputError(f"map_batch: unknown function '{name}'; expected one of {', '.join(_BATCH)}")
    return getattr(hexatwist, name)


def _run_chunk(name: str, model: Model, rows: FloatArray, kwargs: dict[str, Any], row_kwargs: dict[str, Any]) -> Any:
    _hexatwist()
    return _function(name)(model, rows, **kwargs, **row_kwargs)


def _concatenate(parts: list[R]) -> R:
    """One batch result from the results of its chunks, in order: each array concatenated."""
    first = parts[0]
    return dataclasses.replace(first, **{name: np.concatenate([p[name] for p in parts], axis=0) for name in first})


def _per_row(value: Any, n: int) -> bool:
    """True for a keyword array with one row per input row (cut with the rows), not one value for all."""
    if not isinstance(value, np.ndarray) or value.ndim == 0 or value.shape[0] != n:
        return False
    return not (value.ndim == 1 and value.shape[0] == 6)  # a (6,) array is one pose for every row


@overload
def map_batch(function: Literal["commands"], model: Model, array: ArrayLike, client: Any = None,
              chunk: int | None = None, **kwargs: Any) -> Commands:
    ...


@overload
def map_batch(function: Literal["forward"], model: Model, array: ArrayLike, client: Any = None,
              chunk: int | None = None, **kwargs: Any) -> ForwardKinematics:
    ...


@overload
def map_batch(function: Literal["twist"], model: Model, array: ArrayLike, client: Any = None,
              chunk: int | None = None, **kwargs: Any) -> Twist:
    ...


@overload
def map_batch(function: Literal["inverse_kinematics"], model: Model, array: ArrayLike, client: Any = None,
              chunk: int | None = None, **kwargs: Any) -> InverseKinematics | LegLengths:
    ...


@overload
def map_batch(function: str, model: Model, array: ArrayLike, client: Any = None, chunk: int | None = None,
              **kwargs: Any) -> Result:
    ...


def map_batch(function: str, model: Model, array: ArrayLike, client: Any = None, chunk: int | None = None,
              **kwargs: Any) -> Result:
    """Evaluates a batch function ("inverse_kinematics", "twist", "commands" or "forward") over an
    (N, 6) float64 array, in chunks of ``chunk`` rows (default 64 * BLOCK; rounded up to a multiple of
    BLOCK) on the workers of ``client`` (a dask.distributed.Client), or locally when ``client`` is None
    (one call: the library's own threads). ``kwargs`` go to the function (strategy=, kind=, guess=, ...);
    an array with one row per input row (``guess=`` (N, 6)) is cut into the same chunks, each sent with
    its own. Returns the same typed result as the local call, bit for bit."""
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
        result: Result = fn(model, rows, **kwargs)
        return result
    kwargs = {k: (np.asarray(v) if isinstance(v, (list, tuple)) else v) for k, v in kwargs.items()}
    per_row = {k: v for k, v in kwargs.items() if _per_row(v, len(rows))}
    common = {k: v for k, v in kwargs.items() if k not in per_row}
    block = hexatwist.BLOCK
    chunk = 64 * block if chunk is None else max(1, -(-int(chunk) // block)) * block
    starts = list(range(0, len(rows), chunk)) or [0]
    # Random keys (hash=False): a content key would be the one an earlier call's data had, which
    # the scheduler may still be releasing when the same rows come again (its task then cancelled).
    model_future = client.scatter(model, broadcast=True, hash=False)
    futures = []
    for i in starts:
        piece = client.scatter(np.ascontiguousarray(rows[i:i + chunk]), hash=False)
        row_kwargs = {k: client.scatter(np.ascontiguousarray(v[i:i + chunk]), hash=False) for k, v in per_row.items()}
        futures.append(client.submit(_run_chunk, function, model_future, piece, common, row_kwargs, pure=False))
    parts: list[Result] = client.gather(futures)
    return _concatenate(parts)


def _simulate(kwargs: dict[str, Any]) -> Simulation:
    result: Simulation = _hexatwist().simulate(**kwargs)
    return result


def map_simulations(runs: Iterable[Mapping[str, Any]], client: Any = None,
                    max_workers: int | None = None) -> list[Simulation]:
    """Runs :func:`hexatwist.simulate` once per item of ``runs`` (dicts of its keyword arguments: rig (a
    Rig, or YAML text), test or poses, strategy, ...) on the workers of ``client``, or on local threads
    (``max_workers``, default the CPU count; simulate releases the GIL) when ``client`` is None.
    Returns the list of results in the order of ``runs``."""
    kwargs = [dict(r) for r in runs]
    if client is None:
        with ThreadPoolExecutor(max_workers=max_workers or os.cpu_count() or 1) as pool:
            return list(pool.map(_simulate, kwargs))
    results: list[Simulation] = client.gather([client.submit(_simulate, r, pure=False) for r in kwargs])
    return results


# ---- design studies on a cluster: the library's raw results (dicts), typed by hexatwist.design -------


def _ranges(total: int, chunk: int) -> list[tuple[int, int]]:
    return [(first, min(chunk, total - first)) for first in range(0, total, chunk)]


def _volume_task(model: Model, grid: dict[str, Any], step: float, tolerance: float, strategy: str, first: int,
                 count: int) -> Any:
    return _hexatwist()._core._volume_cells(model, grid, step, tolerance, strategy, first, count)


def _workspace_volume_on(client: Any, model: Model, orientation: ArrayLike, cell: float, refine: int, step: float,
                        tolerance: float, strategy: str, chunk: int | None) -> dict[str, Any]:
    """hexatwist.workspace_volume on the workers: the grid (bounds arithmetic) here, its cells there,
    ``chunk`` cells a task (default: the grid in about 32 tasks of whole rows), their sums here."""
    core = _hexatwist()._core
    grid = core._volume_grid(model, orientation, cell, refine, step, tolerance, strategy)
    n = grid["cells"]
    chunk = int(chunk) if chunk else grid["nx"] * max(1, math.ceil(grid["ny"] / 32))
    model_future = client.scatter(model, broadcast=True, hash=False)
    futures = [client.submit(_volume_task, model_future, grid, step, tolerance, strategy, first, count, pure=False)
               for first, count in _ranges(n, max(1, chunk))]
    parts = client.gather(futures)
    fine = np.concatenate([p[0] for p in parts])
    coarse = np.concatenate([p[1] for p in parts])
    volume: dict[str, Any] = core._volume_from_cells(grid, fine, coarse, sum(int(p[2]) for p in parts))
    return volume


def _map_grid_task(model: Model, orientation: tuple[float, ...], plane: str, offset: float, spacing: float,
                   step: float, tolerance: float, strategy: str) -> Any:
    return _hexatwist()._core._map_grid(model, orientation, plane, offset, spacing, step, tolerance, strategy)


def _map_task(model: Model, orientation: tuple[float, ...], grid: dict[str, Any], strategy: str, first: int,
              count: int) -> Any:
    return _hexatwist()._core._workspace_map_rows(model, orientation, grid, strategy, first, count)


def _workspace_map_on(client: Any, model: Model, orientation: ArrayLike, plane: str | None, offset: float | None,
                     spacing: float | None, grid: dict[str, Any] | None, step: float | None, tolerance: float | None,
                     strategy: str, chunk: int | None) -> tuple[dict[str, Any], dict[str, Any]]:
    """hexatwist.workspace_map on the workers: the grid (a slice search) in one task, then ``chunk``
    rows a task (default: about 32 tasks). Returns the rows stacked in order, with the library's
    values (legs as 0-based indices, what ``python3 -m hexatwist.cluster`` hands the command line),
    and the grid."""
    model_future = client.scatter(model, broadcast=True, hash=False)
    rpy = tuple(float(x) for x in np.asarray(orientation, dtype=np.float64))
    if grid is None:
        grid = client.submit(_map_grid_task, model_future, rpy, plane, offset, spacing, step, tolerance, strategy,
                             pure=False).result()
    assert grid is not None
    chunk = int(chunk) if chunk else max(1, math.ceil(grid["nv"] / 32))
    futures = [client.submit(_map_task, model_future, rpy, grid, strategy, first, count, pure=False)
               for first, count in _ranges(grid["nv"], chunk)]
    parts: list[dict[str, Any]] = client.gather(futures)
    return {key: np.concatenate([p[key] for p in parts], axis=0) for key in parts[0]}, grid


def _tolerance_task(platform: Any, poses: Any, workspace: dict[str, Any], sigmas: dict[str, float], seed: int,
                    first: int, count: int, calibration: str, linear_worst: bool, tracker: Any) -> Any:
    hexatwist = _hexatwist()
    return hexatwist._core._tolerance_chunk(platform, poses, workspace, sigmas, seed, first, count, calibration,
                                            linear_worst, hexatwist.get_num_threads(), tracker)


def _linear_task(platform: Any, poses: Any, workspace: dict[str, Any], sigmas: dict[str, float], calibration: str,
                 tracker: Any, seed: int) -> Any:
    hexatwist = _hexatwist()
    return hexatwist._core._tolerance_linear(platform, poses, workspace, sigmas, hexatwist.get_num_threads(),
                                             calibration, tracker, seed)


_HISTOGRAMS = ("histogram_point", "histogram_position", "histogram_orientation")


def _merge_tolerance_chunks(parts: list[dict[str, Any]]) -> dict[str, Any]:
    """One study from its chunks (in platform order): the per-platform arrays concatenated, the
    histograms added (integer counts)."""
    parts = sorted(parts, key=lambda p: int(p["first"]))
    out: dict[str, Any] = {"first": parts[0]["first"]}
    for key in parts[0]:
        if key == "first":
            continue
        if key in _HISTOGRAMS:
            out[key] = np.sum([p[key] for p in parts], axis=0, dtype=np.uint64)
        else:
            out[key] = np.concatenate([p[key] for p in parts])
    return out


def _tolerance_on(client: Any, platform: Any, poses: ArrayLike | None, workspace: dict[str, Any],
                 sigmas: dict[str, float], seed: int, platforms: int, calibration: str, linear_worst: bool,
                 chunk: int | None, linear: bool = True, tracker: Any = None) -> tuple[dict[str, Any], Any]:
    """hexatwist.tolerance on the workers: ``chunk`` platforms a task (default: about 64 tasks), each
    sampling its platforms from (seed, index) and generating the poses from ``workspace`` (``poses``,
    when given, are scattered once), a tracker calibration's noise from (seed, index) too; one task for
    the covariance answer (``linear``). Returns (chunk, linear or None)."""
    chunk = int(chunk) if chunk else max(1, math.ceil(platforms / 64))
    platform_future = client.scatter(platform, broadcast=True, hash=False) if platform is not None else None
    poses_future = client.scatter(np.ascontiguousarray(poses, dtype=np.float64), broadcast=True, hash=False) \
        if poses is not None else None
    linear_future = client.submit(_linear_task, platform_future, poses_future, workspace, sigmas, calibration, tracker,
                                  seed, pure=False) if linear else None
    futures = [client.submit(_tolerance_task, platform_future, poses_future, workspace, sigmas, seed, first, count,
                             calibration, linear_worst, tracker, pure=False)
               for first, count in _ranges(platforms, chunk)]
    return _merge_tolerance_chunks(client.gather(futures)), \
        linear_future.result() if linear_future is not None else None
