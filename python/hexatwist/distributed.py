"""Batch evaluations and simulation sweeps over a dask.distributed cluster, or local threads.

The work is cut into chunks of a fixed number of rows, a multiple of ``hexatwist.BLOCK``, that do not
depend on the cluster: each chunk runs the same library code as a local call on the same rows, and
forward kinematics warm-starts on BLOCK boundaries only, so the concatenated result is identical, bit
for bit, to the local run.

Pointing it at a cluster::

    # on the scheduler host                 # on each worker host (hexatwist importable there)
    dask scheduler --port 8786              dask worker tcp://scheduler-host:8786 --nthreads 1 --nworkers 2

    from dask.distributed import Client
    client = Client("tcp://scheduler-host:8786")
    r = hexatwist.map_batch("commands", model, poses, client=client)
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

_BATCH = ("inverse_kinematics", "twist", "commands", "forward")


def _function(name):
    import hexatwist

    if name not in _BATCH:
        raise hexatwist.InputError(f"map_batch: unknown function '{name}'; expected one of {', '.join(_BATCH)}")
    return getattr(hexatwist, name)


def _run_chunk(name, model, rows, kwargs):
    return dict(_function(name)(model, rows, **kwargs))


def _concatenate(parts):
    import hexatwist

    out = hexatwist.Result()
    for key in parts[0]:
        out[key] = np.concatenate([p[key] for p in parts], axis=0)
    return out


def map_batch(function: str, model, array, client=None, chunk: int | None = None, **kwargs):
    """Evaluates a batch function ("inverse_kinematics", "twist", "commands" or "forward") over an
    (N, 6) float64 array, in chunks of ``chunk`` rows (default 64 * BLOCK; rounded up to a multiple of
    BLOCK) on the workers of ``client`` (a dask.distributed.Client), or locally when ``client`` is None
    (one call: the library's own threads). ``kwargs`` go to the function (strategy=, kind=, ...).
    Returns the same Result as the local call, bit for bit."""
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
    block = hexatwist.BLOCK
    chunk = 64 * block if chunk is None else max(1, -(-int(chunk) // block)) * block
    pieces = [np.ascontiguousarray(rows[i:i + chunk]) for i in range(0, len(rows), chunk)] or [rows]
    model_future = client.scatter(model, broadcast=True)
    futures = [client.submit(_run_chunk, function, model_future, client.scatter(p), kwargs, pure=False)
               for p in pieces]
    return _concatenate(client.gather(futures))


def _simulate(kwargs):
    import hexatwist

    return hexatwist.simulate(**kwargs)


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
