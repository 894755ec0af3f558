# SPDX-License-Identifier: BSD-3-Clause
"""Simulation (the library's simulation subsystem: servo, simulation, study): the closed loop of the
six servo drives and the platform, and the paper's study (the same test with twist-free,
conventional and compensated commands). Every function takes the :class:`~hexatwist.Rig` first (YAML
text, a path or None for the seed are built for that call). A limit or a numerical failure during a
run is the summary's status (with the sample, the time and the leg, 1 to 6), not an exception.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

from . import _hexatwist as _core
from ._hexatwist import MAX_TRAJECTORY_SAMPLES
from .core import ArrayLike, FloatArray, Result, _fields
from .dynamics import RigLike
from .kinematics import Strategy

__all__ = [
    "MAX_TRAJECTORY_SAMPLES", "simulate", "study", "study_trajectory", "TimeSeries", "Simulation",
    "SimulationSummary", "Study", "StudySummary", "StrategySummary", "ErrorStats", "EffectCost",
]

TestName = Literal["Lz", "Lx", "Rz", "Ry"]


@dataclass(frozen=True)
class TimeSeries(Result):
    """A closed-loop run, one sample per control period: (T,) and (T, 6) arrays."""

    time: FloatArray
    """(T,) [s]"""
    desired: FloatArray
    """(T, 6) the pose commanded [m, rad]."""
    actual: FloatArray
    """(T, 6) the pose reached [m, rad]."""
    command: FloatArray
    """(T, 6) motor-side commands [m]."""
    encoder: FloatArray
    """(T, 6) motor-side lengths the encoders read [m]."""
    motor: FloatArray
    """(T, 6) motor-side lengths [m]."""
    length: FloatArray
    """(T, 6) real joint-to-joint lengths [m]."""
    twist: FloatArray
    """(T, 6) [rad]"""
    torque: FloatArray
    """(T, 6) motor torques [N m]."""
    error: FloatArray
    """(T,) observation error: distance of point A from where it was commanded [m]."""
    error_twist_only: FloatArray
    """(T,) the same with perfect servos: the twist's share [m]."""


@dataclass(frozen=True)
class SimulationSummary(Result):
    """How a run ended."""

    status: str
    """"ok", or the limit or numerical failure that stopped it."""
    index: int
    """Sample where it stopped (0-based)."""
    time: float
    """Its time [s]."""
    leg: int
    """The leg (1 to 6) of that limit; 0: none, or the whole platform."""
    value: float
    """The limit's value [m, rad, rad/s or N m]."""
    bound: float
    """Its bound."""
    error_max: float | None
    """Largest observation error [m]; None unless the status is ok."""
    error_rms: float | None
    """RMS observation error [m]; None unless the status is ok."""
    ticks: int
    """Samples simulated."""


@dataclass(frozen=True)
class Simulation(TimeSeries):
    """A closed-loop simulation (simulation.hpp): the time series and how it ended."""

    summary: SimulationSummary


@dataclass(frozen=True)
class ErrorStats(Result):
    """Largest and RMS of an error series [m]."""

    max: float
    rms: float


@dataclass(frozen=True)
class StrategySummary(Result):
    """One strategy's run of a study test (study.hpp's run_metrics: what summary.json reports)."""

    total: ErrorStats
    """The observation error [m]."""
    twist_only: ErrorStats
    """Its twist's share, perfect servos [m]."""
    tracking_only: ErrorStats
    """The twist-free run's, the servos' share [m]."""
    max_torque: float
    """[N m]"""
    saturated_ticks: int
    """Ticks a motor spent at its torque limit."""
    max_following_error: float
    """Largest motor-side following error [m]."""
    max_orientation_error: float
    """Largest orientation error of the platform [rad]."""


@dataclass(frozen=True)
class EffectCost(Result):
    """What one of the legs' effects costs at point A over the test, perfect servos (effect_cost.hpp;
    summary.json's ``leg_effects``)."""

    effect: str
    """"load", "play", "heat" (each alone on otherwise rigid legs) or "all"."""
    conventional: ErrorStats
    """Commands that ignore the twist and the effect [m]."""
    twist_compensated: ErrorStats
    """Eq. (12) alone: the twist compensated, the effect not [m]."""
    compensated: ErrorStats
    """Both compensated, the legs' forces known along the test (its accelerations included) [m]."""
    static_load_compensated: ErrorStats
    """Both compensated with the forces of the static load at the pose (what ``commands`` gives:
    the trajectory's accelerations unknown); the same as ``compensated`` without a stiffness [m]."""


@dataclass(frozen=True)
class StudySummary(Result):
    """The verdict of one study test."""

    status: str
    """"ok", or the limit or numerical failure that stopped a run."""
    index: int
    time: float
    leg: int
    """The leg (1 to 6) of that limit; 0: none."""
    value: float
    bound: float
    test: str
    """Lz, Lx, Rz, Ry, or "poses"."""
    conventional: StrategySummary | None
    """None unless the status is ok."""
    compensated: StrategySummary | None
    """None unless the status is ok."""
    leg_effects: tuple[EffectCost, ...]
    """One per effect the configuration's legs have (empty for rigid legs, or unless the status is ok)."""


@dataclass(frozen=True)
class Study(Result):
    """One test of the paper's study (§4, Table 1)."""

    conventional: TimeSeries
    compensated: TimeSeries
    tracking_only: FloatArray
    """(T,) observation error of the twist-free run [m]."""
    summary: StudySummary


def study_trajectory(rig: RigLike = None, test: TestName = "Rz") -> FloatArray:
    """Poses (T, 6) [m, rad] of one of the paper's tests (Lz, Lx, Rz, Ry), one per control period."""
    return _core.study_trajectory(rig, test)


def _series(d: dict[str, Any]) -> TimeSeries:
    return TimeSeries(**d)


def simulate(rig: RigLike = None, test: TestName | None = None, poses: ArrayLike | None = None,
             strategy: Strategy = "compensated", twist_in_plant: bool = True) -> Simulation:
    """Closed-loop simulation under the six servo loops (simulation.hpp) of one of the paper's tests
    (``test``: Lz, Lx, Rz, Ry; Rz when neither is given) or of ``poses`` (T, 6) [m, rad], one per control
    period (at most ``MAX_TRAJECTORY_SAMPLES``); both is an InputError. ``twist_in_plant=False``: a
    platform without twist (the servos' share alone)."""
    d = _core._simulate(rig, test, poses, strategy, twist_in_plant)
    summary = SimulationSummary(**d.pop("summary"))
    return Simulation(**d, summary=summary)


def study(rig: RigLike = None, test: TestName | None = None, poses: ArrayLike | None = None,
          temperature_rise: float | ArrayLike = 0.0) -> Study:
    """One test of the paper's study (§4, Table 1): the twist-free, conventional and compensated runs of
    ``test`` (Lz, Lx, Rz, Ry; Rz when neither is given) or of ``poses`` (T, 6) [m, rad], not both; the
    summary's metrics are what ``hexatwist study`` reports in summary.json, number for number. For a
    configuration with ``leg_effects``, ``summary.leg_effects`` says what each costs, the legs warming
    by ``temperature_rise`` [K] (one or six) over the test (``hexatwist study --temperature-rise-k``)."""
    d = _core._study(rig, test, poses, temperature_rise)
    s = dict(d["summary"])
    s["leg_effects"] = tuple(EffectCost(effect=e["effect"], **{k: ErrorStats(**e[k]) for k in
                                                               ("conventional", "twist_compensated", "compensated",
                                                                "static_load_compensated")})
                             for e in s["leg_effects"])
    for name in ("conventional", "compensated"):
        if s[name] is not None:
            s[name] = StrategySummary(**_fields(s[name], **{k: ErrorStats(**s[name][k])
                                                            for k in ("total", "twist_only", "tracking_only")}))
    return Study(conventional=_series(d["conventional"]), compensated=_series(d["compensated"]),
                 tracking_only=d["tracking_only"], summary=StudySummary(**s))
