# SPDX-License-Identifier: BSD-3-Clause
"""Kinematics (the library's kinematics subsystem): inverse kinematics, twist and the length error it
causes, motor-side commands with their limits, forward kinematics (one batch, or along a motion),
the real-time command stream, and the reach along each coordinate. Every function takes the
:class:`Model` first.

Poses are rows ``[x, y, z, roll, pitch, yaw]`` relative to home: x, y, z [m] in the base frame B,
roll, pitch, yaw [rad] with R = Rz(yaw) Ry(pitch) Rx(roll) (paper Eq. 3). Batch functions take an
(N, 6) float64 array (or one (6,) pose, which gives (6,) rows and 0-d statuses), never copy a
C-contiguous float64 input, release the GIL and spread the work over the threads
(:func:`~hexatwist.set_num_threads`) in blocks of ``BLOCK`` poses: the results do not depend on
the threads. Legs are numbered 1 to 6 in every ``leg`` field (0: none); the six columns of the
per-leg arrays are legs 1 to 6.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, TypedDict, Union, overload

import numpy as np

from . import _hexatwist as _core
from ._hexatwist import BLOCK, Model
from .core import ArrayLike, FloatArray, Int8Array, Int32Array, PerPose, Result

__all__ = [
    "BLOCK", "COORDINATES", "Strategy", "LengthKind", "Model", "Limits", "inverse_kinematics", "twist", "length_error", "platform_points",
    "commands",
    "motor_command", "forward", "FkTracker", "forward_kinematics_tracked", "Stream", "axis_range",
    "InverseKinematics", "LegLengths", "Twist", "Commands", "ForwardKinematics", "TrackedForwardKinematics",
    "StreamCommand", "LimitReport", "AxisRange",
]

COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")
"""The six pose coordinates in their order: x, y, z [m], roll, pitch, yaw [rad]."""

Strategy = Literal["compensated", "conventional"]
"""The motor-side commands: "compensated" (Eq. 12, the twist taken out) or "conventional" (the twist ignored)."""
LengthKind = Literal["motor", "geometric"]
"""Leg lengths as the motors see them ("motor": the twist included) or joint to joint ("geometric")."""


class Limits(TypedDict):
    """A model's limits (``Model.limits``)."""

    length_min: float  #: shortest joint-to-joint leg length [m]
    length_max: float  #: longest [m]
    bend_max: float  #: largest U-joint bend from home [rad]
    singularity_margin: float  #: smallest angle between a leg and a fixed U-joint axis's normal plane [rad]
    jacobian_condition_max: float  #: largest condition number of the platform Jacobian [-]


@dataclass(frozen=True)
class InverseKinematics(PerPose):
    """Inverse kinematics of N poses (paper Eq. 1-4)."""

    lengths: FloatArray
    """(N, 6) joint-to-joint leg lengths [m]."""
    axes: FloatArray
    """(N, 6, 3) unit leg axes, base joint to platform joint [-, B]."""
    bend_base: FloatArray
    """(N, 6) base U-joint bends from home [rad]."""
    bend_platform: FloatArray
    """(N, 6) platform U-joint bends from home [rad]."""
    status: Int8Array
    """(N,) ok, or stroke_below_min for a zero-length leg (limits are not checked here)."""


@dataclass(frozen=True)
class LegLengths(PerPose):
    """Leg lengths alone (``inverse_kinematics(..., lengths_only=True)``): the same numbers bit for bit."""

    lengths: FloatArray
    """(N, 6) joint-to-joint leg lengths [m]."""
    status: Int8Array
    """(N,) status codes."""


@dataclass(frozen=True)
class Twist(PerPose):
    """Twist of each leg relative to home and the length error it causes (Eq. 7-10)."""

    twist: FloatArray
    """(N, 6) passive rotation of each rod in its housing about the leg axis [rad] (signed, atan2 form)."""
    length_error: FloatArray
    """(N, 6) real minus motor-side length the twist causes, Eq. (10) [m]."""
    status: Int8Array
    """(N,) ok, or singular_base / singular_platform where a leg is parallel to a fixed U-joint axis (NaN rows)."""


@dataclass(frozen=True)
class Commands(PerPose):
    """Motor-side commands of N poses with their limits checked (the library's motor_commands, Eq. 11-12)."""

    commands: FloatArray
    """(N, 6) motor-side leg lengths [m]; NaN rows where the status is not ok: never send those."""
    status: Int8Array
    """(N,) status codes: ok, or the first limit crossed."""
    limit_leg: Int8Array
    """(N,) the leg (1 to 6) of the first limit crossed; 0: none, or the platform Jacobian's condition."""
    limit_value: FloatArray
    """(N,) the value that crossed it [m, rad or -]."""
    limit_bound: FloatArray
    """(N,) the bound it crossed, in the same unit."""


@dataclass(frozen=True)
class ForwardKinematics(PerPose):
    """Forward kinematics of N sets of six leg lengths (Newton on R^3 x SO(3))."""

    poses: FloatArray
    """(N, 6) poses [m, rad]; NaN rows unless ok."""
    status: Int8Array
    """(N,) ok, no_convergence, singular_jacobian, ... ."""
    iterations: Int32Array
    """(N,) Newton iterations."""
    residual: FloatArray
    """(N,) largest |length residual| at the solution [m]."""


@dataclass(frozen=True)
class TrackedForwardKinematics(PerPose):
    """Forward kinematics along a motion (forward_kinematics_tracked): rows solved in order."""

    poses: FloatArray
    """(N, 6) poses [m, rad]; NaN rows unless ok."""
    status: Int8Array
    """(N,) ok, assembly_mode_changed, platform_singularity, no_convergence, ... ."""
    iterations: Int32Array
    """(N,) Newton iterations."""
    residual: FloatArray
    """(N,) largest |length residual| [m]."""
    condition: FloatArray
    """(N,) condition number of the platform Jacobian at the solution [-]."""
    det_sign: FloatArray
    """(N,) sign of the Jacobian's determinant: the assembly mode [-]."""


@dataclass(frozen=True)
class StreamCommand(Result):
    """The stream's answer to one input pose."""

    input: int
    """1-based number of the input."""
    status: str
    """"ok", or why the pose was rejected (a limit, "non_finite_input", ...)."""
    action: Literal["new", "held", "none"]
    """"new" command, the last one "held", or "none" to send."""
    rate_limited: bool
    """The command was slowed down by the rate limits."""
    command: FloatArray | None
    """(6,) motor-side command to send [m]; None when the action is "none"."""
    leg: int
    """The leg (1 to 6) of the limit that rejected the pose; 0: none, or the whole platform."""
    value: float
    """That limit's value [m, rad or -]."""
    bound: float
    """That limit's bound, in the same unit."""


@dataclass(frozen=True)
class LimitReport(Result):
    """A limit met: which, at which leg, by how much."""

    status: str
    """The limit's status name ("stroke_above_max", ...), or "ok" for none."""
    leg: int
    """Its leg, 1 to 6; 0: none, or the whole platform (the Jacobian's condition)."""
    value: float
    """The value beyond the bound [m, rad or -]."""
    bound: float
    """The bound, in the same unit."""


@dataclass(frozen=True)
class AxisRange(Result):
    """Reach along one pose coordinate, the others at home (the library's axis_range)."""

    coordinate: str
    """"x", "y", "z", "roll", "pitch" or "yaw"."""
    lower: float
    """Smallest reachable value, <= 0 [m or rad]."""
    upper: float
    """Largest reachable value, >= 0 [m or rad]."""
    lower_limit: LimitReport
    """The limit met just below ``lower`` (status "ok": the search bound)."""
    upper_limit: LimitReport
    """The limit met just above ``upper``."""


@overload
def inverse_kinematics(model: Model, poses: ArrayLike, lengths_only: Literal[False] = False) -> InverseKinematics:
    ...


@overload
def inverse_kinematics(model: Model, poses: ArrayLike, lengths_only: Literal[True]) -> LegLengths:
    ...


@overload
def inverse_kinematics(model: Model, poses: ArrayLike, lengths_only: bool) -> InverseKinematics | LegLengths:
    ...


def inverse_kinematics(model: Model, poses: ArrayLike, lengths_only: bool = False) -> InverseKinematics | LegLengths:
    """Inverse kinematics, paper Eq. (1)-(4), of (N, 6) poses [m, rad]: :class:`InverseKinematics`
    (lengths, unit axes, U-joint bends, status; limits are not checked here). ``lengths_only=True``
    returns :class:`LegLengths`, the same lengths and statuses bit for bit, with the poses across the
    SIMD lanes (the library's leg_lengths_batch): a fraction of the time."""
    if lengths_only:
        return LegLengths._of(_core._ik(model, poses, True))
    return InverseKinematics._of(_core._ik(model, poses, False))


def twist(model: Model, poses: ArrayLike) -> Twist:
    """Twist (the passive rotation of each rod relative to its housing about the leg axis) relative to
    home, and the length error it causes, Eq. (10), of (N, 6) poses [m, rad] (theory §3)."""
    return Twist._of(_core._twist(model, poses))


def length_error(model: Model, poses: ArrayLike) -> FloatArray:
    """Length error of each leg from its twist, Eq. (10): (N, 6) real minus motor-side length [m]
    (NaN where the twist is undefined; :func:`twist` gives the statuses)."""
    return twist(model, poses).length_error


def platform_points(model: Model, poses: ArrayLike, point: ArrayLike | None = None) -> FloatArray:
    """Where a point of the platform is in the base frame at each of (N, 6) poses: (N, 3) [m, B] (the
    library's platform_point_B). ``point`` [m, P]: None for the observation point A. This is where the
    platform puts the point for the poses that :func:`forward` finds; its distance to the point at the
    commanded poses is the observation error."""
    return _core._platform_points(model, poses, point)


def commands(model: Model, poses: ArrayLike, strategy: Strategy = "compensated") -> Commands:
    """Motor-side commands for (N, 6) poses [m, rad], every limit checked (the library's
    motor_commands_batch, each pose bit for bit motor_commands' result). ``strategy``: "compensated"
    (Eq. 12: IK length - offset - twist_gain * twist) or "conventional" (the twist ignored)."""
    return Commands._of(_core._commands(model, poses, strategy))


def motor_command(model: Model, pose: ArrayLike, strategy: Strategy = "compensated") -> FloatArray:
    """Motor-side commands (6,) [m] for one pose [x, y, z m, roll, pitch, yaw rad] relative to home: the
    library's real-time motor_commands (Eq. 11-12, limits checked). Raises StatusError outside a limit
    (naming the leg, 1 to 6), InputError for NaN or a malformed pose."""
    return _core.motor_command(model, pose, strategy)


def forward(model: Model, lengths: ArrayLike, kind: LengthKind = "motor", guess: ArrayLike | None = None,
            max_iterations: int = 30, tolerance: float = 1e-12) -> ForwardKinematics:
    """Forward kinematics (Newton on R^3 x SO(3)) of (N, 6) leg lengths [m].

    ``kind``: "motor" (motor-side lengths, twist included: solves IK - offset - twist_gain * twist = m)
    or "geometric" (joint-to-joint lengths). ``guess``: None warm-starts along the batch (each block of
    ``BLOCK`` rows starts at home, then from the previous solution: the same numbers on any number of
    threads or Dask chunks that are multiples of BLOCK); a (6,) pose starts every row there, an (N, 6)
    array each row at its own. ``tolerance`` [m] on the length residual."""
    return ForwardKinematics._of(_core._forward(model, lengths, kind, guess, max_iterations, tolerance))


class FkTracker(_core.FkTracker):
    """Forward kinematics along a motion (forward.hpp, forward_kinematics_tracked): each solve starts from
    the last solution and is ok only on the same assembly mode (the sign of the Jacobian's determinant)
    and with the Jacobian's condition inside ``limits["jacobian_condition_max"]`` (else
    platform_singularity); a failed row leaves the tracker as it was. ``FkTracker(model, kind="motor",
    start=None)``: starts at home (or at the pose ``start`` [m, rad]) until :meth:`set` or the first
    solution."""

    def track(self, lengths: ArrayLike, max_iterations: int = 30, tolerance: float = 1e-12) -> TrackedForwardKinematics:
        """Solves (N, 6) or (6,) leg lengths [m] in order (GIL released)."""
        return TrackedForwardKinematics._of(self._track(lengths, max_iterations, tolerance))


def forward_kinematics_tracked(model: Model, lengths: ArrayLike, kind: LengthKind = "motor",
                               start: ArrayLike | None = None, max_iterations: int = 30,
                               tolerance: float = 1e-12) -> TrackedForwardKinematics:
    """Forward kinematics along a motion with one :class:`FkTracker`: rows of ``lengths`` (N, 6) [m]
    solved in order, each from the last solution, ok only on the start's assembly mode and away from a
    platform singularity. ``start``: None (home) or a pose [m, rad]."""
    return FkTracker(model, kind, start).track(lengths, max_iterations, tolerance)


class Stream(_core.Stream):
    """The real-time command stream (stream.hpp): one pose in, one checked set of six motor-side commands
    out; a rejected pose is answered with its status and the held command (or none). ``Stream(model,
    strategy="compensated", on_reject="hold" | "skip", period=1e-3 [s], max_velocity=inf [m/s],
    max_acceleration=inf [m/s^2])``, the rate limits per leg command; :meth:`start` at the pose the
    platform stands at, then :meth:`pose` once per period."""

    def pose(self, pose: ArrayLike) -> StreamCommand:
        """One input pose [x, y, z m, roll, pitch, yaw rad]: the command to send and why."""
        return StreamCommand._of(self._pose(pose))


def axis_range(model: Model, coordinate: Union[int, str], strategy: Strategy = "compensated", *,
               linear_step: float = 1e-3, angular_step: float = 1e-3, linear_bound: float = 10.0,
               angular_bound: float = float(np.pi), tolerance: float = 1e-9) -> AxisRange:
    """Reach along one pose coordinate alone, the others at home (workspace.hpp, axis_range):
    ``coordinate`` "x", "y", "z", "roll", "pitch", "yaw" or 0..5. ``lower`` <= 0 <= ``upper`` [m or rad]
    inside every limit for the commands of ``strategy``, marched in ``linear_step`` [m] /
    ``angular_step`` [rad] up to ``linear_bound`` [m] / ``angular_bound`` [rad] and bisected to
    ``tolerance``, and the limits met just beyond. Raises StatusError when home is outside a limit."""
    d = _core._axis_range(model, coordinate, strategy, linear_step, angular_step, linear_bound, angular_bound,
                          tolerance)
    return AxisRange(coordinate=d["coordinate"], lower=d["lower"], upper=d["upper"],
                     lower_limit=LimitReport(**d["lower_limit"]), upper_limit=LimitReport(**d["upper_limit"]))
