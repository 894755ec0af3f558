# SPDX-License-Identifier: BSD-3-Clause
"""Calibration (the library's calibration subsystem): a laser tracker's point log, the commanded runs
of a measurement (a measured test, a run of stations), the observations at rest, the twist-aware
identification (theory §13) with the library's decisions, and rigid registration (Kabsch). The
identification takes the nominal :class:`~hexatwist.Model` first; the commanded runs take the
:class:`~hexatwist.Rig` (its control period and study). Stations are numbered from 1, as the command
line reports them; observation and log indices are 0-based.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Literal, Union

import numpy as np

from . import _hexatwist as _core
from ._hexatwist import Model
from .core import ArrayLike, FloatArray, Int32Array, IntArray, Result, _fields
from .dynamics import RigLike
from .kinematics import Strategy

__all__ = [
    "read_point_log", "measured_test", "stations_run", "observations_at_rest", "identify", "register_points",
    "plan_stations", "PointLog", "CommandedRun", "StationsRun", "Observations", "Identification", "CorrectedPlatform",
    "StationsQuality", "StationPlan",
    "StationResidual", "SignFit", "CrossValidation", "PredictedAccuracy", "Registration",
    "compare", "PlatformComparison", "LegDifference", "CommandAccuracy",
]


@dataclass(frozen=True)
class PointLog(Result):
    """A laser tracker's point log (point_log.hpp)."""

    stamps: FloatArray
    """(K,) times [s] (or sample indices of an indexed log)."""
    points: FloatArray
    """(K, 3) the targets as measured [m, tracker frame T]."""
    targets: Int32Array
    """(K,) each point's target: an index into ``target_names`` (0: the observation point)."""
    target_names: tuple[str, ...]
    """The targets' names in order of first appearance."""
    lines: Int32Array
    """(K,) each point's line in the file (1-based)."""
    temperatures: FloatArray
    """(K,) the machine's temperature at each point [degC], from a temperature column; (0,) without one."""
    source: str
    """The log's name in messages."""


@dataclass(frozen=True)
class CommandedRun(Result):
    """The commanded run of a measured test: calibration moves, then the study test."""

    t: FloatArray
    """(T,) [s]"""
    poses: FloatArray
    """(T, 6) [m, rad] at the control rate."""
    calibration_end: float
    """End of the calibration moves [s]."""


@dataclass(frozen=True)
class StationsRun(Result):
    """A calibration run of stations (stations.hpp): home, each station for 1 s, home."""

    t: FloatArray
    """(T,) [s]"""
    poses: FloatArray
    """(T, 6) [m, rad] at the control rate."""
    stations: FloatArray
    """(N, 6) the stations [m, rad]."""


@dataclass(frozen=True)
class Observations(Result):
    """The log points taken at rest, each with the motor-side lengths commanded there."""

    motor: FloatArray
    """(K, 6) commanded motor-side lengths [m]."""
    points: FloatArray
    """(K, 3) the points as measured [m, T]."""
    targets: Int32Array
    """(K,) target indices (0: the observation point)."""
    time: FloatArray
    """(K,) each observation's time in the run [s] (for identify's heat effect)."""
    temperature: FloatArray
    """(K,) the machine's temperature at each observation [degC] (NaN without a temperature column;
    with them, identify's heat fits each leg's expansion per kelvin)."""
    approach: FloatArray
    """(K, 6) each leg's approach to the station: the last monotone run of its command, positive
    lengthening, negative shortening [m] (for identify's play effect)."""
    index: IntArray
    """(K,) each observation's row in the log (0-based)."""
    stations: int
    """Stations among them (runs of one commanded pose)."""


@dataclass(frozen=True)
class CorrectedPlatform(Result):
    """The identified platform's numbers (rows and entries: legs 1 to 6)."""

    base_joints: FloatArray
    """(6, 3) base joint centres [m, B]."""
    platform_joints: FloatArray
    """(6, 3) platform joint centres [m, P]."""
    base_axes: FloatArray
    """(6, 3) fixed base U-joint axes [-, B]."""
    platform_axes: FloatArray
    """(6, 3) fixed platform U-joint axes [-, P]."""
    leads: FloatArray
    """(6,) screw leads [m]."""
    thread_hands: tuple[str, ...]
    """"right" or "left" per leg."""
    length_offsets: FloatArray
    """(6,) real minus motor-side length at zero twist [m]."""
    home_commands: FloatArray
    """(6,) the drives' reference: motor-side lengths at home [m]."""
    drive_leads: FloatArray
    """(6,) the leads the drives scale with [m]."""
    observation_point: FloatArray
    """(3,) point A [m, P]."""


@dataclass(frozen=True)
class StationResidual(Result):
    """A station with a large residual."""

    station: int
    """The station, numbered from 1."""
    target: int
    """Its target index (0: the observation point)."""
    first: int
    """Its first observation (0-based)."""
    count: int
    """Its observations."""
    mean_error: float
    """|mean residual| [m]."""
    statistic: float
    """Its share of the fit test [-]."""


@dataclass(frozen=True)
class SignFit(Result):
    """The solve with the thread sense held at one value."""

    twist_sign: float
    """+1: every hand as configured, -1: all flipped."""
    status: str
    cost: float
    """Half the sum of squared residuals [m^2]."""
    iterations: int
    lead_at_bound: bool
    """A lead ended at 0: this sense cannot explain the twist."""


@dataclass(frozen=True)
class CrossValidation(Result):
    """Stations left out and predicted (theory §13)."""

    folds: int
    """0: not done."""
    predicted: int
    """Groups predicted."""
    rms: float
    """RMS of the predicted groups' mean residual [m]."""
    expected: float
    """What the tracker's noise and the covariance make it expected to be [m]."""
    max: float
    """Largest predicted group's mean residual [m]."""


@dataclass(frozen=True)
class PredictedAccuracy(Result):
    """The corrected platform's predicted accuracy over the calibrated range (theory §13)."""

    poses: int
    """Poses evaluated."""
    median: float
    """Median predicted point error [m]."""
    max: float
    """Largest [m]."""
    aligned_median: float
    """The same after the best rigid re-alignment of the frames [m]."""
    aligned_max: float
    range_low: FloatArray
    """(6,) the stations' smallest pose [m, rad]."""
    range_high: FloatArray
    """(6,) and largest."""


@dataclass(frozen=True)
class Identification(Result):
    """The twist-aware calibration (identification.hpp): the same status and estimate as
    ``hexatwist identify``. The estimate, sd and covariance are meaningful when ``fitted``; the
    corrected platform when the status is "ok"."""

    status: str
    """"ok", "not_identifiable", "model_mismatch", "sign_undecided", ... ."""
    reason: str
    """One line, for a status other than ok."""
    hint: str
    """What to do about it (may be empty)."""
    fitted: bool
    effects: str
    """The legs' effects fitted, "load,play,heat" or a part of it, or "none" (theory §13b)."""
    effects_choice: str
    """With ``effects="auto"``: how they were chosen, one line ("" otherwise)."""
    parameter_names: tuple[str, ...]
    calibration: Literal["geometry", "basic"]
    nominal: FloatArray
    """The nominal model's parameters (SI)."""
    estimate: FloatArray
    """In ``parameter_names`` order [m; rad for the tracker rotation as dw about R_BT]."""
    sd: FloatArray
    """Standard deviations, the same order."""
    covariance: FloatArray
    twist_sign: float
    """+1: the thread hands as configured, -1: all flipped."""
    R_BT: FloatArray
    """(3, 3) the tracker frame's rotation in B."""
    t_BT: FloatArray
    """(3,) its origin [m, B]."""
    corrected: CorrectedPlatform | None
    """The corrected platform's numbers when fitted."""
    corrected_model: Model | None
    """The corrected Model when the status is ok (:func:`~hexatwist.corrected_config` writes it)."""
    base_shift: FloatArray
    """(6, 3) the base joint centres' displacement [m, B]."""
    base_shift_sd: FloatArray
    platform_shift: FloatArray
    """(6, 3) the platform joint centres' displacement [m, P]."""
    platform_shift_sd: FloatArray
    axis_sd: FloatArray
    """(12,) the axes' predicted sd, legs 1 to 6 base then platform [rad]."""
    axes_fitted: tuple[bool, ...]
    targets: tuple[FloatArray, ...]
    """Each target's point [m, P] (the observation point first)."""
    observations: int
    stations: int
    groups: int
    sigma: float
    """The fit's noise per coordinate [m]."""
    tracker_noise: float
    """The tracker noise the test uses [m]."""
    scatter: float
    """The scatter at rest [m]."""
    fit_statistic: float
    fit_z: float
    """The model-fit test's normal deviate."""
    unexplained: float
    """What the model leaves beyond the tracker's noise, per point and coordinate [m]."""
    diagnosis: dict[str, float]
    """On a refusal: each effect not fitted ("load", "play", "heat"), its drop of the fit statistic
    when added [sigma] (NaN where it cannot be fitted)."""
    rms_before: float
    """RMS 3-D residual of the nominal model after Kabsch [m]."""
    rms_after: float
    """At the estimate [m]."""
    max_after: float
    cost_ratio: float
    sign_separation: float
    condition: float
    fit_dof: int
    max_after_index: int
    """The observation with the largest residual (0-based)."""
    undetermined: str
    """The parameters in undetermined combinations."""
    worst: tuple[StationResidual, ...]
    residuals: FloatArray
    """(K, 3) per observation [m, B]."""
    fits: tuple[SignFit, ...]
    """Both thread senses: +1, -1."""
    cross_validation: CrossValidation
    accuracy: PredictedAccuracy


@dataclass(frozen=True)
class Registration(Result):
    """Best-fit rigid transform X_BT (registration.hpp): p_B ~ R_BT p_T + t_BT."""

    status: str
    """"ok", "too_few_points" or "degenerate_registration"."""
    R_BT: FloatArray
    """(3, 3)"""
    t_BT: FloatArray
    """(3,) [m, B]"""
    count: int
    rms_residual: float
    """[m]"""
    max_residual: float
    """[m]"""
    max_residual_index: int
    """The pair with the largest residual (0-based)."""
    sigma: float
    """Noise per coordinate [m]."""
    singular_values: FloatArray
    """(3,) [m^2]"""
    reflection: bool
    condition: float


def read_point_log(path_or_text: Union[str, os.PathLike[str]], time_column: str = "t", length_unit: float = 0.0,
                   indexed: bool = False, target_column: str = "",
                   temperature_column: str = "") -> PointLog:
    """A laser tracker's point log (CSV with a header; point_log.hpp). Units come from the column
    suffixes (``x_mm``, ``t_s``) or ``length_unit`` [m per unit]; a ``target`` column (or
    ``target_column``) names each row's target; a ``temperature`` or ``temperature_c`` column (or
    ``temperature_column``) gives the machine's temperature [degC]. Raises ConfigError with the library's
    "source:line:column: ..." message."""
    d = _core._read_point_log(path_or_text, time_column, length_unit, indexed, target_column, temperature_column)
    return PointLog(**_fields(d, target_names=tuple(d["target_names"])))


def measured_test(rig: RigLike = None, test: Literal["Lz", "Lx", "Rz", "Ry"] = "Rz") -> CommandedRun:
    """The commanded run of a measured test: calibration moves then the study test."""
    return CommandedRun(**_core._measured_test(rig, test))


def stations_run(rig: RigLike = None, count: int = 40, seed: int = 1,
                 strategy: Strategy = "compensated", translation: float = 0.25,
                 rotation: float = float(np.radians(15.0)), stations: ArrayLike | None = None,
                 approach: float = 0.0, reference_every: int = 0) -> StationsRun:
    """A calibration run (stations.hpp): home, ``count`` random stations within +-``translation`` [m] and
    +-``rotation`` [rad] inside every limit (the same seed gives the command line's ``--stations N
    --station-seed S`` run), or the given ``stations`` (N, 6) [m, rad]; 1 s at each, then home. With
    ``approach`` [m] each station is approached from that far above and below (``--both-sides-mm``),
    with ``reference_every`` N home is visited again after every N stations (``--reference-every``)."""
    return StationsRun(**_core._stations_run(rig, count, seed, strategy, translation, rotation, stations, approach,
                                             reference_every))


def observations_at_rest(model: Model, t: ArrayLike, poses: ArrayLike, stamps: ArrayLike, points: ArrayLike,
                         targets: ArrayLike | None = None, time_offset: float = 0.0,
                         strategy: Strategy = "compensated",
                         settle: float = 0.25, temperatures: ArrayLike | None = None) -> Observations:
    """The log points (``stamps`` (K,) [s], ``points`` (K, 3) [m, T], ``targets``) taken while the
    commanded run (``t`` (T,) [s], ``poses`` (T, 6)) had been still for ``settle`` [s], each with the
    motor-side lengths the model commands there. ``time_offset``: log time at run time 0 [s];
    ``temperatures`` (K,) [degC]: the log's temperature column, if any."""
    d = _core._observations_at_rest(model, np.asarray(t, dtype=np.float64), poses,
                                    np.asarray(stamps, dtype=np.float64), points, targets, time_offset, strategy,
                                    settle, None if temperatures is None else np.asarray(temperatures, dtype=np.float64))
    return Observations(**_fields(d, index=np.asarray(d["index"], dtype=np.int_)))


@dataclass(frozen=True)
class StationsQuality(Result):
    """How well a run's stations determine the model (station_plan.hpp, theory §13 "Where to measure")."""

    status: str
    """"ok", or why the stations do not determine the model ("not_identifiable", ...)."""
    reason: str
    """One line, for a status other than ok."""
    stations: FloatArray
    """(N, 6) in run order, home not included [m, rad]."""
    criterion: float
    """The Ds criterion: log det of the platform parameters' information, the tracker frame a nuisance
    [log of m^-2]."""
    sd_geometric: float
    """The geometric mean of the parameters' standard deviations [m]."""
    condition: float
    """Condition number of the column-scaled Jacobian, as identify computes it (at most 1e6)."""
    path: float
    """Length of the moves home, stations, home in pose coordinates [m or rad]."""
    covariance: FloatArray
    """(p, p) of the platform parameters (``StationPlan.parameter_names``) [m^2]."""
    sd: FloatArray
    """(p,) their standard deviations."""
    accuracy: PredictedAccuracy
    """The predicted point error over the range from that covariance."""


@dataclass(frozen=True)
class StationPlan(Result):
    """Where to measure (station_plan.hpp): the planned stations of a calibration run, the same plan as
    ``hexatwist stations --json``, beside random stations of the same count and seed."""

    status: str
    """"ok", or why not ("not_identifiable": too few poses inside the limits, ...)."""
    reason: str
    """One line, for a status other than ok."""
    stations: FloatArray
    """(N, 6) the planned stations in run order [m, rad]; ``stations_run(rig, stations=...)`` is the run."""
    parameter_names: tuple[str, ...]
    """The platform parameters planned for."""
    candidates: int
    """Candidate poses inside every limit."""
    draws: int
    """Poses drawn to find them."""
    sweeps: int
    """Exchange sweeps."""
    exchanges: int
    """Stations exchanged after the greedy start."""
    converged: bool
    """The last sweep made no exchange."""
    replaced: int
    """Stations replaced while ordering (their move left a limit)."""
    planned: StationsQuality
    random: StationsQuality
    """Random stations of the same count and seed (``stations_run``'s)."""


def _quality(d: dict[str, Any]) -> StationsQuality:
    return StationsQuality(**_fields(d, accuracy=PredictedAccuracy(**d["accuracy"])))


def plan_stations(rig: RigLike = None, count: int = 20, seed: int = 1, strategy: Strategy = "compensated",
                  translation: float = 0.25, rotation: float = float(np.radians(15.0)), candidates: int = 3000,
                  calibration: Literal["geometry", "basic"] = "geometry", noise: float = 10e-6,
                  points_per_station: int = 75, accuracy_poses: int = 1000) -> StationPlan:
    """Where to measure (station_plan.hpp, theory §13): ``count`` stations chosen from ``candidates``
    poses drawn with ``seed`` within +-``translation`` [m] and +-``rotation`` [rad] inside every limit
    that maximise the Ds criterion (the ``calibration`` model's information, the tracker frame a
    nuisance) by an exchange algorithm, in run order: the same plan as ``hexatwist stations --json``.
    ``noise`` [m] and ``points_per_station`` scale the predicted accuracy, not the choice. A value out
    of its range raises InputError naming its keyword."""
    d = _core._plan_stations(rig, count, seed, strategy, translation, rotation, candidates, calibration, noise,
                             points_per_station, accuracy_poses)
    return StationPlan(**_fields(d, parameter_names=tuple(d["parameter_names"]), planned=_quality(d["planned"]),
                                 random=_quality(d["random"])))


def _identification(d: dict[str, Any]) -> Identification:
    return Identification(**_fields(
        d, parameter_names=tuple(d["parameter_names"]), axes_fitted=tuple(d["axes_fitted"]),
        targets=tuple(d["targets"]),
        corrected=None if d["corrected"] is None else CorrectedPlatform(**d["corrected"]),
        worst=tuple(StationResidual(**w) for w in d["worst"]), fits=tuple(SignFit(**f) for f in d["fits"]),
        cross_validation=CrossValidation(**d["cross_validation"]), accuracy=PredictedAccuracy(**d["accuracy"])))


def identify(model: Model, motor: ArrayLike, points: ArrayLike, targets: ArrayLike | None = None, *,
             calibration: Literal["geometry", "basic"] = "geometry", lead_effect: Literal["travel", "twist"] = "travel",
             axes: Literal["auto", "none", "all"] = "auto", tracker_noise: float | None = None, folds: int = 5,
             accuracy_poses: int = 1000, effects: str = "auto", times: ArrayLike | None = None,
             approach: ArrayLike | None = None, temperatures: ArrayLike | None = None) -> Identification:
    """Calibrates the platform (identification.hpp, theory §13) from observations ``motor`` (K, 6) [m],
    ``points`` (K, 3) [m, T] and their ``targets`` (K,) int (None: all the observation point), with the
    library's decisions: the same status and estimate as ``hexatwist identify`` (whose defaults these are).

    ``calibration``: "geometry" (the twelve U-joint centres, leads, thread sense, offsets, targets,
    tracker frame) or "basic" (the joints as configured); ``lead_effect`` "travel" | "twist"; ``axes``
    "auto" | "none" | "all"; ``tracker_noise`` [m] (None: the scatter at rest); ``folds`` of the
    cross-validation (0: none). ``effects``: the legs' effects fitted besides the geometry (theory §13b),
    "load", "play", "heat" comma-separated, "none", or "auto" (those the data show at 5 sigma), as
    ``hexatwist identify --effects``; heat needs each
    observation's ``times`` (K,) [s], play their ``approach`` (K, 6) [m] (both as
    ``observations_at_rest`` gives them; without times, heat is left out, and without approaches the
    stations' order decides; pass both to reach the CLI's result). With ``temperatures`` (K,) [degC]
    (``observations_at_rest``'s ``temperature``, from the log's temperature column), heat fits each
    leg's expansion per kelvin and the lead's, which the corrected configuration keeps. A refusal is
    the status (with a reason and a hint), not an exception."""
    column = None if times is None else np.asarray(times, dtype=np.float64).reshape(-1, 1)
    celsius = None if temperatures is None else np.asarray(temperatures, dtype=np.float64).reshape(-1, 1)
    return _identification(_core._identify(model, motor, points, targets, calibration, lead_effect, axes,
                                           tracker_noise, folds, accuracy_poses, effects, column, approach, celsius))


def register_points(points_T: ArrayLike, points_B: ArrayLike, max_condition: float = 1e4) -> Registration:
    """Best-fit rigid transform X_BT (registration.hpp, Kabsch/Umeyama, no scale) mapping points measured
    in the tracker frame ``points_T`` (N, 3) [m, T] onto the same points ``points_B`` (N, 3) [m, B]."""
    return Registration(**_core._register_points(points_T, points_B, max_condition))


@dataclass(frozen=True)
class LegDifference(Result):
    """One leg of B against the same leg of A, B - A (validation.hpp)."""

    base: FloatArray
    """(3,) base joint centre [m, B]."""
    platform: FloatArray
    """(3,) platform joint centre [m, P]."""
    base_axis_angle: float
    """Angle between the fixed base axes [rad]."""
    platform_axis_angle: float
    """Angle between the fixed platform axes [rad]."""
    lead: float
    """[m]"""
    drive_lead: float
    """[m]"""
    length_offset: float
    """Zero offset [m]."""
    home_command: float
    """The drive's reading at its reference [m]."""
    compliance: float
    """1 / stiffness [m/N]."""
    play: float
    """[m]"""
    thread_differs: bool


@dataclass(frozen=True)
class CommandAccuracy(Result):
    """Where A's compensated commands put point A on B at the stations (validation.hpp)."""

    gauge: FloatArray
    """(N,) the distance at each station in the gauge frames, sorted [m]."""
    aligned: FloatArray
    """(N,) the same after the best rigid re-alignment, sorted [m]."""
    gauge_median: float
    gauge_max: float
    aligned_median: float
    aligned_max: float


@dataclass(frozen=True)
class PlatformComparison(Result):
    """Two platforms compared (``hexatwist compare A B --json``, number for number)."""

    legs: tuple[LegDifference, ...]
    """Legs 1 to 6."""
    observation_point: FloatArray
    """(3,) B - A of point A [m, P]."""
    home_height: float
    """[m]"""
    largest_joint: float
    """The largest joint centre's difference [m]."""
    largest_joint_leg: int
    """Its leg, 1 to 6."""
    largest_joint_side: str
    """"base" or "platform"."""
    accuracy: CommandAccuracy


def compare(a: Model, b: Model, stations: int = 60, station_seed: int = 1, translation: float = 0.25,
            rotation: float = float(np.radians(15.0))) -> PlatformComparison:
    """What differs between the platforms ``a`` and ``b`` leg by leg (B - A), and where ``a``'s
    compensated commands put point A on ``b`` at ``stations`` random stations within
    +-``translation`` [m] and +-``rotation`` [rad] (theory §13c): a corrected configuration against the
    real platform of a rehearsal (synth's FILE.real.yaml), the nominal one or a later calibration."""
    d = _core._compare(a, b, stations, station_seed, translation, rotation)
    return PlatformComparison(**_fields(d, legs=tuple(LegDifference(**leg) for leg in d["legs"]),
                                        accuracy=CommandAccuracy(**d["accuracy"])))
