# SPDX-License-Identifier: BSD-3-Clause
"""What every subsystem of hexatwist shares (the library's core: types, status, error): the exception
types, the status codes, the threads of the batch functions, the array types, and :class:`Result`,
the base of every typed result.

Conventions of the whole package:

* The first argument is what a function computes on: a :class:`~hexatwist.Model` for kinematics,
  the workspace and calibration (geometry only), a :class:`~hexatwist.Rig` for everything that needs
  the drives, the load, the rates or the study's tests (dynamics, simulation, motor sizing, the
  study, commanded runs). A Rig argument also takes YAML text, a path or None (the seed): then it is
  built for that call; build the Rig once and pass it to parse the configuration once.
* Legs are numbered 1 to 6 wherever a number is called a leg: every ``leg`` and ``*_leg`` field and
  array of a result, every message, as the command line's messages and JSON do; 0 means no leg (the
  pose is ok, or the limit is the whole platform's, such as the Jacobian's condition). Per-leg
  columns of arrays (``commands[:, j]``, ``lengths[:, j]``, the rows of ``model.base``) are numpy
  indices, 0 to 5: leg n is column n - 1. Stations are numbered from 1 as well; everything named
  ``index`` or ``*_index``, ``first`` and ``targets`` is a 0-based index.
* SI units: [m], [rad], [s], [N m]. Poses are rows ``[x, y, z, roll, pitch, yaw]`` relative to home.
* Per-pose outcomes of a batch are int8 status codes (``status`` arrays, ``STATUS_NAMES[code]``,
  :class:`Status`); a single outcome is its name (``"ok"``, ``"stroke_above_max"``, ...). Bad
  arguments raise :class:`InputError`, bad files :class:`ConfigError`, both with one line.
"""
from __future__ import annotations

import dataclasses
import enum
import sys
from collections.abc import Iterator, Mapping
from typing import Any, ClassVar, TypeVar, Union

import numpy as np
import numpy.typing as npt

from . import _hexatwist as _core
from ._hexatwist import STATUS_NAMES, ConfigError, DTypeError, Error, InputError, StatusError

__all__ = [
    "STATUS_NAMES", "Status", "Error", "ConfigError", "InputError", "DTypeError", "StatusError", "Result",
    "PerPose", "describe_status", "set_num_threads", "get_num_threads", "FloatArray", "Int8Array", "Int32Array",
    "IntArray", "BoolArray", "ArrayLike",
]

FloatArray = npt.NDArray[np.float64]
"""A float64 array (SI units)."""
Int8Array = npt.NDArray[np.int8]
"""An int8 array: status codes, leg numbers."""
Int32Array = npt.NDArray[np.int32]
"""An int32 array: iteration counts, indices."""
IntArray = npt.NDArray[np.int_]
"""An array of Python-sized integers (int64 here): counts, indices."""
BoolArray = npt.NDArray[np.bool_]
"""A boolean mask."""
ArrayLike = npt.ArrayLike
"""Anything numpy reads as an array (a float64 C-contiguous array is never copied by a batch call)."""


class Status(enum.IntEnum):
    """Status codes of the per-pose ``status`` arrays: the library's hexatwist::Status, in its order
    (``Status(code).name.lower() == STATUS_NAMES[code]``; :func:`describe_status` says what each means)."""

    OK = 0
    NON_FINITE_INPUT = 1
    STROKE_BELOW_MIN = 2
    STROKE_ABOVE_MAX = 3
    BEND_BASE = 4
    BEND_PLATFORM = 5
    SINGULAR_BASE = 6
    SINGULAR_PLATFORM = 7
    NO_CONVERGENCE = 8
    SINGULAR_JACOBIAN = 9
    MOTOR_SPEED_ABOVE_MAX = 10
    TORQUE_ABOVE_MAX = 11
    MALFORMED_INPUT = 12
    TOO_FEW_POINTS = 13
    DEGENERATE_REGISTRATION = 14
    NOT_IDENTIFIABLE = 15
    SOLVER_NO_CONVERGENCE = 16
    PLATFORM_SINGULARITY = 17
    ASSEMBLY_MODE_CHANGED = 18
    INVALID_ARGUMENT = 19
    SIGN_UNDECIDED = 20
    MODEL_MISMATCH = 21


_R = TypeVar("_R", bound="Result")


class Result(Mapping[str, Any]):
    """Base of every typed result: a frozen dataclass of arrays, numbers and nested results, whose
    typed attributes (``r.commands``, ``r.summary.status``) are the API. It is also a read-only
    mapping of its fields (``r["commands"]``, ``dict(r)``, ``for name in r``) for code written against
    the dict results of earlier versions. Results pickle (Dask ships them)."""

    __slots__ = ()
    _names: ClassVar[tuple[str, ...]] = ()

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        cls._names = ()  # filled on first use: the dataclass decorator runs after this hook

    @classmethod
    def _fields(cls) -> tuple[str, ...]:
        if not cls._names:
            cls._names = tuple(f.name for f in dataclasses.fields(cls))
        return cls._names

    @classmethod
    def _of(cls: type[_R], raw: dict[str, Any]) -> _R:
        """The result of the library's ``raw`` fields, without the dataclass constructor's checks: the
        batch and real-time calls' path (0.3 us instead of 1.4 us for a stream's answer).
        tests/python/test_types.py checks that every function's fields are the annotated ones."""
        result = object.__new__(cls)
        result.__dict__.update(raw)
        return result

    def __getitem__(self, name: str) -> Any:
        if name in self._fields():
            return getattr(self, name)
        raise KeyError(name)

    def __iter__(self) -> Iterator[str]:
        return iter(self._fields())

    def __len__(self) -> int:
        return len(self._fields())


class PerPose(Result):
    """A batch result with one status per pose (``status``, int8 codes; 0-d for one (6,) pose)."""

    __slots__ = ()
    status: Int8Array

    @property
    def ok(self) -> BoolArray:
        """Mask of the poses whose status is ok."""
        return np.asarray(self.status == 0)


def describe_status(status: Union[int, Status]) -> str:
    """One-sentence description of a status code."""
    return _core.describe_status(int(status))


_explicit_threads = False


def _worker_threads() -> int | None:
    """The thread count of the Dask worker this process is, or None outside one."""
    distributed = sys.modules.get("distributed")
    if distributed is None:
        return None
    try:
        worker = distributed.get_worker()
    except (ValueError, AttributeError):
        return None
    state = getattr(worker, "state", None)  # distributed >= 2022.10 keeps it there
    n = getattr(state, "nthreads", None) if state is not None else getattr(worker, "nthreads", None)
    return int(n) if n else None


def _follow_worker() -> None:
    """On a Dask worker, hexatwist's threads follow the worker's (``--nthreads``) unless
    :func:`set_num_threads` chose a count."""
    if not _explicit_threads:
        n = _worker_threads()
        if n:
            _core.set_num_threads(n)


def set_num_threads(n: int) -> None:
    """Threads of the batch and design functions (0, the default: every core; on a Dask worker, the
    worker's thread count). Results do not depend on it."""
    global _explicit_threads
    _core.set_num_threads(n)
    _explicit_threads = n != 0
    if n == 0:
        _follow_worker()


def get_num_threads() -> int:
    """Threads the batch and design functions use."""
    _follow_worker()
    return _core.get_num_threads()


def _fields(raw: Mapping[str, Any], **typed: Any) -> dict[str, Any]:
    """The fields of a typed result: the library's ``raw`` numbers, with ``typed`` ones in place of theirs."""
    return {**raw, **typed}


def _per_leg(legs: npt.NDArray[Any]) -> Int8Array:
    """Leg numbers 1 to 6 (0: none) of the library's 0-based leg indices (-1: none)."""
    return np.asarray(legs + 1, dtype=np.int8)

