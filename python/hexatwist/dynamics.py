# SPDX-License-Identifier: BSD-3-Clause
"""Dynamics (the library's dynamics subsystem: rig, mechanism, motor sizing): the :class:`Rig` (the
platform with its drives, load, leg bodies and rates), the inverse and forward dynamics of the whole
mechanism, its mass matrix and energies, and motor sizing along a trajectory. Every function takes
the Rig first (YAML text, a path or None for the seed are accepted and built for that call: build
the Rig once to parse the configuration once).

Poses are ``[x, y, z, roll, pitch, yaw]`` from home; their rates and accelerations are the time
derivatives of those six numbers [m/s, rad/s; m/s^2, rad/s^2]. The one-pose calls take the
platform's velocity x' = [v of the pivot [m/s]; w [rad/s]] in the base frame B (see
:func:`platform_motion`). Torques are at the motor shafts [N m], positive lengthening the leg; the
six columns of per-leg arrays are legs 1 to 6, and every ``leg`` field a leg number 1 to 6.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any, Literal, TypedDict, Union

from . import _hexatwist as _core
from ._hexatwist import TORQUE_TERMS, Rig
from .core import ArrayLike, FloatArray, Int8Array, PerPose, Result, _fields
from .motion import Trajectory

__all__ = [
    "Rig", "RigLike", "TORQUE_TERMS", "ServoSpec", "LoadSpec", "LegBodySpec", "MechanismSpec", "control_period",
    "platform_motion", "inverse_dynamics", "mass_matrix", "bias", "forward_dynamics", "kinetic_energy",
    "potential_energy", "motor_angles", "motor_jacobian", "peak_torque_at", "size_motors", "PlatformMotion",
    "InverseDynamics", "MotorSizing", "SizingSummary", "MotorSummary", "EnvelopeViolation", "Curve",
    "TorqueSpeedFigure",
]

RigLike = Union[Rig, str, "os.PathLike[str]", None]
"""A :class:`Rig`, or what one is built from: YAML text, a path, or None (the embedded seed)."""


class ServoSpec(TypedDict):
    """A Rig's drive (``Rig.servo``), SI."""

    motor_inertia: float  #: rotor [kg m^2]
    screw_inertia: float  #: screw [kg m^2]
    viscous_friction: float  #: [N m s/rad]
    coulomb_friction: float  #: [N m]
    friction_speed: float  #: speed over which the Coulomb friction sets in [rad/s]
    torque_limit: float  #: peak torque [N m]
    max_speed: float  #: [rad/s]
    peak_corner_speed: float  #: the peak torque holds up to this speed [rad/s]
    peak_torque_at_max_speed: float  #: [N m]
    continuous_torque: float  #: [N m]
    gear_ratio: float  #: motor turns per screw turn [-]


class LoadSpec(TypedDict):
    """A Rig's platform and payload (``Rig.load``)."""

    mass: float  #: [kg]
    center_of_mass: FloatArray  #: (3,) [m, P]
    inertia: FloatArray  #: (3, 3) about the centre of mass along P's axes [kg m^2]
    gravity: float  #: along -z of B [m/s^2]


class LegBodySpec(TypedDict):
    """One body of a leg: the housing (on the base U-joint) or the rod (on the platform U-joint)."""

    mass: float  #: [kg]
    center: float  #: from its U-joint along the leg [m]
    axial_inertia: float  #: [kg m^2]
    transverse_inertia: float  #: [kg m^2]


class MechanismSpec(TypedDict):
    """A Rig's leg bodies and screw efficiencies (``Rig.mechanism``)."""

    housing: LegBodySpec
    rod: LegBodySpec
    efficiency: float  #: the screw driven by the motor [-]
    back_efficiency: float  #: the screw driven by the load [-]


@dataclass(frozen=True)
class PlatformMotion(Result):
    """The platform's velocity and acceleration from the pose's time derivatives."""

    velocity: FloatArray
    """(N, 6) [v of the pivot [m/s]; w [rad/s]] in B."""
    acceleration: FloatArray
    """(N, 6) [m/s^2; rad/s^2] in B."""


@dataclass(frozen=True)
class InverseDynamics(PerPose):
    """Motor torques of the whole mechanism (mechanism.hpp, inverse_dynamics), (N, 6) each; NaN rows
    unless ok. The six parts gravity ... friction add up to ``torque`` (to rounding)."""

    torque: FloatArray
    """Motor torque [N m], positive lengthening the leg."""
    angle: FloatArray
    """Motor angle from home [rad]."""
    speed: FloatArray
    """Motor speed [rad/s]."""
    acceleration: FloatArray
    """Motor acceleration [rad/s^2]."""
    power: FloatArray
    """torque * speed [W] (negative: the load drives the motor)."""
    gravity: FloatArray
    """The torque's part holding the weight of every body [N m]."""
    platform_inertia: FloatArray
    """Its part accelerating platform and payload [N m]."""
    velocity_product: FloatArray
    """Its Coriolis and centrifugal part [N m]."""
    legs: FloatArray
    """Its part moving the housings and rods [N m]."""
    drives: FloatArray
    """Its part accelerating rotors and screws [N m]."""
    friction: FloatArray
    """Its friction part, the screw's efficiency included [N m]."""
    screw_force: FloatArray
    """Axial force in the nut, tension positive [N]."""
    thread_speed: FloatArray
    """The nut's sliding along the screw as a motor speed, real length rate / motor gain [rad/s]."""
    thread_dissipation: FloatArray
    """Power the screw's efficiency loses in the thread (>= 0) [W]."""
    status: Int8Array
    """(N,) status codes (limits are not checked here)."""


@dataclass(frozen=True)
class EnvelopeViolation(Result):
    """Where a motor first leaves its torque-speed envelope."""

    check: Literal["speed", "peak_torque", "continuous_torque"]
    """Which part of the envelope."""
    leg: int
    """The motor's leg, 1 to 6."""
    index: int
    """Sample of the trajectory (0-based)."""
    time: float
    """Its time [s]."""
    value: float
    """|speed| [rad/s], |torque| [N m] or RMS torque [N m]."""
    bound: float
    """The bound it exceeds, in the same unit."""


@dataclass(frozen=True)
class MotorSummary(Result):
    """One motor over the whole trajectory."""

    peak_torque: float
    """Largest |torque| [N m]."""
    peak_torque_time: float
    """Its time [s]."""
    rms_torque: float
    """RMS torque [N m]."""
    peak_speed: float
    """Largest |speed| [rad/s]."""
    peak_speed_time: float
    """[s]"""
    peak_power: float
    """Largest power drawn [W]."""
    peak_power_time: float
    """[s]"""
    energy_driven: float
    """Energy the motor puts in [J]."""
    energy_regenerated: float
    """Energy the load gives back [J]."""
    share: dict[str, float]
    """Per torque part (``TORQUE_TERMS``): RMS of the part / RMS torque [-]."""
    peak_usage: float
    """Largest |torque| over the envelope's torque at that speed [-]."""
    peak_usage_time: float
    """[s]"""
    speed_usage: float
    """Peak speed / maximum speed [-]."""
    rms_usage: float
    """RMS torque / continuous torque [-]."""
    violation: EnvelopeViolation | None
    """Where this motor first leaves its envelope, or None."""


@dataclass(frozen=True)
class SizingSummary(Result):
    """The verdict of a motor sizing."""

    status: str
    """"ok", or the pose limit or numerical failure that stopped it."""
    failed_index: int
    """Sample where that status arose (0-based)."""
    failed_time: float
    """Its time [s]."""
    limit_leg: int
    """The leg (1 to 6) of that pose limit; 0: none."""
    limit_value: float
    """Its value [m, rad or -]."""
    limit_bound: float
    """Its bound."""
    samples: int
    """Samples sized."""
    sample_period: float
    """[s]"""
    envelope: Literal["ok", "exceeded"] | None
    """Every motor inside its envelope or not; None unless the status is ok."""
    first_violation: EnvelopeViolation | None
    """The first violation over all motors (the earliest sample, legs in order), or None."""
    motors: tuple[MotorSummary, ...] | None
    """Legs 1 to 6; None unless the status is ok."""


@dataclass(frozen=True)
class Curve(Result):
    """A torque-speed curve."""

    speed: FloatArray
    """(K,) [rad/s]"""
    torque: FloatArray
    """(K,) [N m]"""


@dataclass(frozen=True)
class TorqueSpeedFigure(Result):
    """The data of the torque-speed figure of ``hexatwist dynamics``."""

    operating: tuple[Curve, ...]
    """Each motor's operating points, legs 1 to 6."""
    envelope: Curve
    """The closed peak torque envelope."""
    continuous_torque: float
    """[N m]"""
    max_speed: float
    """[rad/s]"""


@dataclass(frozen=True)
class MotorSizing(Result):
    """Motor sizing along a trajectory (motor_sizing.hpp): per sample (T,) and (T, 6)."""

    time: FloatArray
    """(T,) [s]"""
    poses: FloatArray
    """(T, 6) the trajectory sized [m, rad]."""
    torque: FloatArray
    """(T, 6) [N m]"""
    speed: FloatArray
    """(T, 6) [rad/s]"""
    power: FloatArray
    """(T, 6) [W]"""
    gravity: FloatArray
    """(T, 6) the torque's parts (``TORQUE_TERMS``) [N m] ..."""
    platform_inertia: FloatArray
    velocity_product: FloatArray
    legs: FloatArray
    drives: FloatArray
    friction: FloatArray
    summary: SizingSummary
    """Status, the envelope's verdict, per motor peaks, RMS, energies, shares and usages."""
    figure: TorqueSpeedFigure
    """The torque-speed figure's data."""


def control_period(rig: RigLike = None) -> float:
    """The rig's servo control period [s]: the period of simulate's poses and of size_motors' samples."""
    return _core.control_period(rig)


def platform_motion(poses: ArrayLike, pose_rates: ArrayLike, pose_accelerations: ArrayLike) -> PlatformMotion:
    """The platform's velocity and acceleration (mechanism.hpp, platform_motion) from (N, 6) poses [m, rad]
    and their time derivatives [m/s, rad/s] and [m/s^2, rad/s^2]: w = E(rpy) rpy', w' = E rpy'' + E' rpy'.
    The ``velocity`` is what :func:`mass_matrix`, :func:`forward_dynamics` and the energies take."""
    return PlatformMotion(**_core._platform_motion(poses, pose_rates, pose_accelerations))


def inverse_dynamics(rig: RigLike, poses: ArrayLike, pose_rates: ArrayLike,
                     pose_accelerations: ArrayLike) -> InverseDynamics:
    """Motor torques of the whole mechanism (platform and payload, housings and rods, rotors and screws,
    friction and the screw's efficiency) for (N, 6) poses [m, rad] with their time derivatives
    ``pose_rates`` [m/s, rad/s] and ``pose_accelerations`` [m/s^2, rad/s^2]. Batch like
    :func:`~hexatwist.commands`: GIL released, threads; limits are not checked."""
    return InverseDynamics(**_core._inverse_dynamics(rig, poses, pose_rates, pose_accelerations))


def mass_matrix(rig: RigLike, pose: ArrayLike) -> FloatArray:
    """The mechanism's mass matrix M (6, 6) at ``pose`` [m, rad], every body included: kinetic energy =
    1/2 x'^T M x'; units kg, kg m, kg m^2 by block. Raises StatusError where the pose has no inverse
    kinematics or twist."""
    return _core.mass_matrix(rig, pose)


def bias(rig: RigLike, pose: ArrayLike, velocity: ArrayLike) -> FloatArray:
    """Generalised force of everything but the motors and friction at zero acceleration (velocity
    products minus gravity) (6,) [N; N m, B], so that M x'' + bias = J_phi^T (torque - friction)."""
    return _core.bias(rig, pose, velocity)


def forward_dynamics(rig: RigLike, pose: ArrayLike, velocity: ArrayLike, torque: ArrayLike) -> FloatArray:
    """Platform acceleration x'' (6,) [m/s^2; rad/s^2, B] for the net motor torques ``torque`` (6,) [N m]
    (friction not included: pass torque - friction), from M x'' = J_phi^T torque - bias."""
    return _core.forward_dynamics(rig, pose, velocity, torque)


def kinetic_energy(rig: RigLike, pose: ArrayLike, velocity: ArrayLike) -> float:
    """Kinetic energy of every body [J] at ``pose`` [m, rad] moving with ``velocity`` x'."""
    return _core.kinetic_energy(rig, pose, velocity)


def potential_energy(rig: RigLike, pose: ArrayLike) -> float:
    """Potential energy in gravity of every body, zero at home [J]."""
    return _core.potential_energy(rig, pose)


def motor_angles(rig: RigLike, pose: ArrayLike) -> FloatArray:
    """Motor angles relative to home (6,) [rad] at ``pose`` [m, rad] (twist included)."""
    return _core.motor_angles(rig, pose)


def motor_jacobian(rig: RigLike, pose: ArrayLike) -> FloatArray:
    """Jacobian J_phi (6, 6) of the motor angles: phi' = J_phi x' [rad/m | rad/rad]."""
    return _core.motor_jacobian(rig, pose)


def peak_torque_at(rig: RigLike, speed: float) -> float:
    """The motor's intermittent torque envelope at ``speed`` [rad/s] (its magnitude is used) [N m]."""
    return _core.peak_torque_at(rig, speed)


def _sizing_summary(d: dict[str, Any]) -> SizingSummary:
    s = dict(d)
    v = s.pop("first_violation")
    motors = s.pop("motors")
    return SizingSummary(
        **s,
        first_violation=EnvelopeViolation(**v) if isinstance(v, dict) else None,
        motors=None if not isinstance(motors, list) else tuple(
            MotorSummary(**_fields(m, violation=EnvelopeViolation(**m["violation"]) if m["violation"] else None))
            for m in motors))


def size_motors(rig: RigLike = None, trajectory: Union[str, os.PathLike[str], Trajectory, None] = None, *,
                times: ArrayLike | None = None, poses: ArrayLike | None = None, dt: float | None = None,
                t0: float = 0.0, envelope_points: int = 64) -> MotorSizing:
    """Motor sizing along a trajectory (motor_sizing.hpp, size_motors), as ``hexatwist dynamics`` does.

    The trajectory: ``trajectory`` a CSV file or its text (t, x, y, z, roll, pitch, yaw with unit
    suffixes, see :func:`~hexatwist.read_trajectory`) resampled at the control period, or a
    :class:`~hexatwist.Trajectory`; or ``poses`` (T, 6) [m, rad] with ``times`` (T,) [s] (resampled
    alike), or with a fixed period ``dt`` [s] (default: the control period) from ``t0`` [s]. Rates and
    accelerations are central differences of the poses. A pose limit or a numerical failure is the
    summary's status, not an exception."""
    csv = None if isinstance(trajectory, Trajectory) else trajectory
    if isinstance(trajectory, Trajectory):
        if times is not None or poses is not None or dt is not None:
            raise _core.InputError("size_motors: give a Trajectory, or poses (with times or dt), not both")
        poses, dt, t0 = trajectory.poses, trajectory.dt, float(trajectory.t[0])
    d = _core._size_motors(rig, csv, times, poses, dt, t0, envelope_points)
    figure = d.pop("figure")
    summary = d.pop("summary")
    return MotorSizing(
        **d, summary=_sizing_summary(summary),
        figure=TorqueSpeedFigure(operating=tuple(Curve(**c) for c in figure["operating"]),
                                 envelope=Curve(**figure["envelope"]), continuous_torque=figure["continuous_torque"],
                                 max_speed=figure["max_speed"]))
