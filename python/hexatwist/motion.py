# SPDX-License-Identifier: BSD-3-Clause
"""Motion (the library's motion subsystem, trajectory.hpp): pose trajectories made of jerk-limited
moves (the paper's sweep along one coordinate, straight moves through waypoints) and trajectories
read from CSV and resampled onto a fixed period. A :class:`Trajectory` at the control period is what
:func:`~hexatwist.simulate`, :func:`~hexatwist.study` and :func:`~hexatwist.size_motors` take as
``poses``. Poses are [x, y, z m, roll, pitch, yaw rad] relative to home."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Union

from . import _hexatwist as _core
from .core import ArrayLike, FloatArray, Int32Array, Result

__all__ = ["Trajectory", "TimedPoses", "sweep_trajectory", "waypoint_trajectory", "read_trajectory", "resample"]


@dataclass(frozen=True)
class Trajectory(Result):
    """Poses sampled at a fixed period: ``poses[k]`` at ``t[k] = t[0] + k dt``."""

    t: FloatArray
    """(T,) sample times [s]."""
    poses: FloatArray
    """(T, 6) poses relative to home [m, rad]."""
    dt: float
    """Sample period [s]."""


@dataclass(frozen=True)
class TimedPoses(Result):
    """Poses at strictly increasing, arbitrary times, as a CSV file gives them."""

    t: FloatArray
    """(T,) times [s]."""
    poses: FloatArray
    """(T, 6) poses relative to home [m, rad] (SI, whatever the file's units)."""
    lines: Int32Array
    """(T,) each row's line in the file (1-based, as an editor numbers lines)."""


def sweep_trajectory(coordinate: int, amplitude: float, *, velocity: float, acceleration: float, jerk: float,
                     dwell: float, dt: float) -> Trajectory:
    """The paper's test motion along one coordinate (0..5: x, y, z, roll, pitch, yaw): at rest for
    ``dwell`` [s], home -> +amplitude, dwell, -> -amplitude, dwell, -> home, dwell; each move the
    fastest jerk-limited (seven-segment) move under ``velocity``, ``acceleration``, ``jerk`` [m or rad
    per s, s^2, s^3]. ``amplitude`` [m or rad] > 0; sampled every ``dt`` [s], the last pose exactly
    home. Raises InputError naming the bad argument."""
    return Trajectory(**_core._sweep_trajectory(coordinate, amplitude, velocity, acceleration, jerk, dwell, dt))


def waypoint_trajectory(waypoints: ArrayLike, *, velocity: float, acceleration: float, jerk: float, dwell: float,
                        dt: float) -> Trajectory:
    """Straight-line moves through ``waypoints`` (K, 6) [m, rad] (at least 2): at rest at the first for
    ``dwell`` [s], then to each next one in a jerk-limited move over the Euclidean distance between
    the two poses under ``velocity``, ``acceleration``, ``jerk`` (so give waypoints that differ in
    translations only, or in rotations only), with ``dwell`` after each; sampled every ``dt`` [s],
    the last pose exactly the last waypoint."""
    return Trajectory(**_core._waypoint_trajectory(waypoints, velocity, acceleration, jerk, dwell, dt))


def read_trajectory(path_or_text: Union[str, os.PathLike[str]]) -> TimedPoses:
    """A trajectory CSV (a path, or its text): a header naming t, x, y, z, roll, pitch, yaw with unit
    suffixes (t_s; x_m or x_mm, no suffix: m; roll_rad or roll_deg, no suffix: degrees), one pose a
    row, times strictly increasing. Raises ConfigError "source:line:column: ..." for a bad file."""
    return TimedPoses(**_core._read_trajectory(path_or_text))


def resample(t: ArrayLike, poses: ArrayLike, dt: float) -> Trajectory:
    """Poses at times ``t`` (T,) [s] resampled every ``dt`` [s] from t[0] to t[-1] with the monotone
    piecewise-cubic (PCHIP) interpolation per coordinate: C1, never beyond the samples, lines exact
    (the library's resample, as ``hexatwist simulate --trajectory`` reads a file)."""
    return Trajectory(**_core._resample(t, poses, dt))
