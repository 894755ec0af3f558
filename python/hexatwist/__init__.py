"""hexatwist: twist-aware kinematics of lead-screw (U-P-U) Stewart platforms, from numpy.

Poses are rows ``[x, y, z, roll, pitch, yaw]`` relative to home: x, y, z [m] in the base frame B,
roll, pitch, yaw [rad] with R = Rz(yaw) Ry(pitch) Rx(roll) (paper Eq. 3). Batch functions take an
(N, 6) float64 array (or one (6,) pose), never copy a C-contiguous float64 input, release the GIL
and spread the work over all cores. Per-pose outcomes are int8 status codes (``STATUS_NAMES[code]``,
0 = ok); bad arguments raise :class:`InputError` (a ValueError) with a one-line message, a bad
configuration :class:`ConfigError`.
"""
from __future__ import annotations

import enum
import os
import sys

import numpy as np

from ._hexatwist import (  # noqa: F401  (re-exported)
    BLOCK,
    MAX_TRAJECTORY_SAMPLES,
    HISTOGRAM_BINS,
    STATUS_NAMES,
    ConfigError,
    DTypeError,
    Error,
    FkTracker,
    InputError,
    Model,
    Rig,
    StatusError,
    Stream,
    TORQUE_TERMS,
)
from . import _hexatwist as _core


def _exported(name):
    """The compiled function ``name`` as a Python function of this package. A pybind11 function is
    bound to a PyCapsule, which does not pickle; this one pickles by reference (``hexatwist.<name>``),
    so it can be shipped to Dask workers (``client.run(hexatwist.get_num_threads)``)."""
    compiled = getattr(_core, name)

    def function(*args, **kwargs):
        return compiled(*args, **kwargs)

    function.__name__ = function.__qualname__ = name
    function.__module__ = __name__
    function.__doc__ = compiled.__doc__
    return function


_input_copies = _exported("_input_copies")
bias = _exported("bias")
control_period = _exported("control_period")
default_model = _exported("default_model")
describe_status = _exported("describe_status")
forward_dynamics = _exported("forward_dynamics")
kinetic_energy = _exported("kinetic_energy")
load_model = _exported("load_model")
mass_matrix = _exported("mass_matrix")
mjcf = _exported("mjcf")
motor_angles = _exported("motor_angles")
def _motor_command_function():
    compiled = _core.motor_command

    # The one-pose call is the one whose cost matters: its arguments spelt out (about 25 ns over the
    # compiled function, where *args, **kwargs cost 150 ns).
    def motor_command(model, pose, strategy="compensated"):
        return compiled(model, pose, strategy)

    motor_command.__module__, motor_command.__qualname__ = __name__, "motor_command"
    motor_command.__doc__ = compiled.__doc__
    return motor_command


motor_command = _motor_command_function()
motor_jacobian = _exported("motor_jacobian")
peak_torque_at = _exported("peak_torque_at")
potential_energy = _exported("potential_energy")
seed_config_yaml = _exported("seed_config_yaml")
study_trajectory = _exported("study_trajectory")
tilt_torsion_rotation = _exported("tilt_torsion_rotation")

_explicit_threads = False


def _worker_threads():
    """The thread count of the Dask worker this process is, or None outside one."""
    distributed = sys.modules.get("distributed")
    if distributed is None:
        return None
    try:
        worker = distributed.get_worker()
    except (ValueError, AttributeError):
        return None
    state = getattr(worker, "state", None)  # distributed >= 2022.10 keeps it there
    return getattr(state, "nthreads", None) if state is not None else getattr(worker, "nthreads", None)


def _follow_worker():
    """On a Dask worker, hexatwist's threads follow the worker's (``--nthreads``) unless
    :func:`set_num_threads` chose a count."""
    if not _explicit_threads:
        n = _worker_threads()
        if n:
            _core.set_num_threads(int(n))


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


_follow_worker()

from .distributed import map_batch, map_simulations  # noqa: E402,F401
from . import distributed as _distributed  # noqa: E402

__all__ = [
    "BLOCK", "MAX_TRAJECTORY_SAMPLES", "STATUS_NAMES", "Status", "Result", "Error", "ConfigError", "InputError", "DTypeError", "StatusError",
    "Model", "Stream", "default_model", "load_model", "seed_config_yaml", "control_period", "study_trajectory",
    "inverse_kinematics", "twist", "length_error", "commands", "motor_command", "forward",
    "simulate", "study", "read_point_log", "measured_test", "observations_at_rest", "identify",
    "map_batch", "map_simulations", "describe_status", "set_num_threads", "get_num_threads",
    "Rig", "TORQUE_TERMS", "platform_motion", "inverse_dynamics", "mass_matrix", "bias", "forward_dynamics",
    "kinetic_energy", "potential_energy", "motor_angles", "motor_jacobian", "peak_torque_at", "size_motors",
    "FkTracker", "forward_kinematics_tracked", "register_points", "axis_range", "COORDINATES", "mjcf",
    "HISTOGRAM_BINS", "workspace_volume", "workspace_slice", "orientation_workspace", "tilt_torsion_rotation",
    "workspace_map", "required_workspace", "design_axes", "tolerance",
]

COORDINATES = ("x", "y", "z", "roll", "pitch", "yaw")

Status = enum.IntEnum("Status", [(name.upper(), code) for code, name in enumerate(STATUS_NAMES)])
Status.__doc__ = "Status codes of the per-pose ``status`` arrays (the library's hexatwist::Status)."


class Result(dict):
    """The arrays of a batch call: a dict whose keys are also attributes (``r.commands``)."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(name) from None

    def __dir__(self):
        return list(self.keys()) + list(super().__dir__())

    def __reduce__(self):
        return (Result, (dict(self),))

    @property
    def ok(self):
        """Boolean mask of the poses whose status is ok."""
        return self["status"] == 0


def inverse_kinematics(model: Model, poses, lengths_only: bool = False) -> Result:
    """Inverse kinematics, paper Eq. (1)-(4), of (N, 6) poses [m, rad].

    Returns ``lengths`` (N, 6) joint-to-joint leg lengths [m], ``axes`` (N, 6, 3) unit leg axes base to
    platform [-, B], ``bend_base`` and ``bend_platform`` (N, 6) U-joint bends from home [rad], and
    ``status`` (N,) int8 (ok, or stroke_below_min for a zero-length leg; limits are not checked here).
    ``lengths_only=True`` returns ``lengths`` and ``status`` alone, the same numbers bit for bit, with
    the poses across the SIMD lanes (the library's leg_lengths_batch): a fraction of the time.
    """
    return Result(_core._ik(model, poses, lengths_only))


def twist(model: Model, poses) -> Result:
    """Twist (passive rotation of each rod relative to its housing about the leg axis) relative to home.

    Returns ``twist`` (N, 6) [rad] (signed, atan2 form; docs/theory.md §3), ``length_error`` (N, 6)
    real minus motor-side length it causes, Eq. (10) [m], and ``status`` (N,) int8 (singular_base /
    singular_platform where a leg is parallel to a fixed U-joint axis: NaN rows).
    """
    return Result(_core._twist(model, poses))


def length_error(model: Model, poses) -> np.ndarray:
    """Length error of each leg from its twist, Eq. (10): (N, 6) real minus motor-side length [m]
    (NaN where the twist is undefined; see :func:`twist` for the statuses)."""
    return _core._twist(model, poses)["length_error"]


def commands(model: Model, poses, strategy: str = "compensated") -> Result:
    """Motor-side commands for (N, 6) poses [m, rad], limits checked (the library's motor_commands).

    ``strategy``: "compensated" (Eq. 12: IK length - offset - twist_gain * twist) or "conventional"
    (twist ignored). Returns ``commands`` (N, 6) [m] (NaN rows where the status is not ok: never send
    those), ``status`` (N,) int8, and the first limit crossed: ``limit_leg`` (N,) int8 0-based (-1:
    none or the platform Jacobian), ``limit_value`` and ``limit_bound`` (N,) [m, rad or -].
    """
    return Result(_core._commands(model, poses, strategy))


def forward(model: Model, lengths, kind: str = "motor", guess=None, max_iterations: int = 30,
            tolerance: float = 1e-12) -> Result:
    """Forward kinematics (Newton on R^3 x SO(3)) of (N, 6) leg lengths [m].

    ``kind``: "motor" (motor-side lengths, twist included: solves IK - offset - twist_gain * twist = m)
    or "geometric" (joint-to-joint lengths). ``guess``: None warm-starts along the batch (each block of
    ``BLOCK`` rows starts at home, then from the previous solution: the same numbers on any number of
    threads or Dask chunks that are multiples of BLOCK); a (6,) pose starts every row there, an (N, 6)
    array each row at its own. Returns ``poses`` (N, 6) [m, rad] (NaN unless ok), ``status`` (N,) int8
    (ok, no_convergence, singular_jacobian, assembly_mode_changed, ...), ``iterations`` (N,) int32 and
    ``residual`` (N,) largest |length residual| [m].
    """
    return Result(_core._forward(model, lengths, kind, guess, max_iterations, tolerance))


def simulate(config=None, test: str | None = None, poses=None, strategy: str = "compensated",
             twist_in_plant: bool = True) -> Result:
    """Closed-loop simulation under the six servo loops (simulation.hpp).

    ``config``: YAML text, a path, or None for the embedded seed configuration. The trajectory is one
    of the paper's tests (``test``: Lz, Lx, Rz, Ry; Rz when neither is given) or ``poses`` (T, 6) [m, rad]
    one per control period (at most ``MAX_TRAJECTORY_SAMPLES``); both is an InputError. Returns time series ``time`` (T,) [s]; ``desired``, ``actual`` poses (T, 6) [m, rad]; ``command``,
    ``encoder``, ``motor`` motor-side and ``length`` real lengths (T, 6) [m]; ``twist`` (T, 6) [rad];
    ``torque`` (T, 6) [N m]; observation errors ``error``, ``error_twist_only`` (T,) [m]; and
    ``summary`` (dict: status, issue index/time/leg/value/bound, error_max, error_rms [m] (None unless the
    status is ok), ticks).
    """
    r = Result(_core._simulate(config, test, poses, strategy, twist_in_plant))
    for k, v in list(r.items()):
        if isinstance(v, dict) and k != "summary":
            r[k] = Result(v)
    return r


def study(config=None, test: str | None = None, poses=None) -> Result:
    """One test of the paper's study (§4, Table 1): the twist-free, conventional and compensated runs of
    ``test`` (Lz, Lx, Rz, Ry; Rz when neither is given) or of ``poses`` (T, 6) [m, rad], not both.

    Returns ``conventional`` and ``compensated`` (each a Result of time series as :func:`simulate`),
    ``tracking_only`` (T,) observation error of the twist-free run [m], and ``summary``: status (a limit or
    numerical failure with its index/time/leg/value/bound), and per strategy (None unless the status is ok)
    the max / rms of the total, twist-only and tracking-only errors [m] and what ``hexatwist study`` reports
    beside them in summary.json (the library's run_metrics): ``max_torque`` [N m], ``saturated_ticks``,
    ``max_following_error`` [m] and ``max_orientation_error`` [rad].
    """
    r = Result(_core._study(config, test, poses))
    r["conventional"] = Result(r["conventional"])
    r["compensated"] = Result(r["compensated"])
    return r


def read_point_log(path_or_text, time_column: str = "t", length_unit: float = 0.0, indexed: bool = False,
                   target_column: str = "") -> Result:
    """A laser tracker's point log (CSV with a header; point_log.hpp): ``stamps`` (K,) [s] (or sample
    indices), ``points`` (K, 3) [m, tracker frame T], ``targets`` (K,) int (an index into
    ``target_names``; 0 is the observation point), ``lines`` (K,) source lines. Units come from the
    column suffixes (``x_mm``, ``t_s``) or ``length_unit`` [m per unit]; a ``target`` column (or
    ``target_column``) names each row's target. Raises ConfigError with the library's
    "source:line:column: ..." message."""
    return Result(_core._read_point_log(path_or_text, time_column, length_unit, indexed, target_column))


def measured_test(config=None, test: str = "Rz") -> Result:
    """The commanded run of a measured test: calibration moves then the study test. ``t`` (T,) [s],
    ``poses`` (T, 6) [m, rad], ``calibration_end`` [s]."""
    return Result(_core._measured_test(config, test))


def stations_run(config=None, count: int = 40, seed: int = 1, strategy: str = "compensated",
                 translation: float = 0.25, rotation: float = float(np.radians(15.0)), stations=None) -> Result:
    """A calibration run (stations.hpp): home, ``count`` random stations within +-``translation`` [m] and
    +-``rotation`` [rad] inside every limit (the same seed gives the CLI's ``--stations N --station-seed S``
    run), or the given ``stations`` (N, 6) [m, rad], home; 1 s at each. ``t`` (T,) [s], ``poses`` (T, 6)
    [m, rad] at the control rate, ``stations`` (N, 6)."""
    return Result(_core._stations_run(config, count, seed, strategy, translation, rotation, stations))


def observations_at_rest(model: Model, t, poses, stamps, points, targets=None, time_offset: float = 0.0,
                         strategy: str = "compensated", settle: float = 0.25) -> Result:
    """The log points taken while the commanded pose had been still for ``settle`` [s], each with the
    motor-side lengths the model commands there: ``motor`` (K, 6) [m], ``points`` (K, 3) [m, T],
    ``targets`` (K,), ``index`` (log rows), ``poses`` (stations). ``time_offset``: log time at trajectory
    t = 0 [s]."""
    return Result(_core._observations_at_rest(model, np.asarray(t, dtype=np.float64), poses,
                                              np.asarray(stamps, dtype=np.float64), points, targets, time_offset,
                                              strategy, settle))


def identify(model: Model, motor, points, targets=None, *, calibration: str = "geometry",
             lead_effect: str = "travel", axes: str = "auto", tracker_noise=None, folds: int = 5,
             accuracy_poses: int = 1000) -> Result:
    """Calibrates the platform (identification.hpp, theory §13) from observations ``motor`` (K, 6) [m],
    ``points`` (K, 3) [m, T] and their ``targets`` (K,) int (None: all the observation point), with the
    library's decisions: the same status and estimate as ``hexatwist identify`` (whose defaults these are).

    ``calibration``: "geometry" (the twelve U-joint centres, leads, thread sense, offsets, targets,
    tracker frame) or "basic" (the joints as configured); ``lead_effect`` "travel" | "twist"; ``axes``
    "auto" | "none" | "all"; ``tracker_noise`` [m] (None: the scatter at rest); ``folds`` of the
    cross-validation (0: none).

    Returns ``status`` ("ok", "not_identifiable", "model_mismatch", "sign_undecided", ...), ``reason``
    and ``hint``; ``parameter_names``, ``nominal``, ``estimate``, ``sd``, ``covariance`` (SI, the tracker
    rotation as dw about ``R_BT``); ``twist_sign``; ``R_BT``, ``t_BT`` [m, B]; ``corrected`` (dict of the
    corrected platform: base_joints, platform_joints (6, 3) [m], axes, leads, threads, length_offsets,
    home_commands, drive_leads [m], observation_point) and ``corrected_model`` (a Model when ok);
    ``base_shift``/``platform_shift`` and their ``_sd`` (6, 3) [m]; ``axis_sd`` (12,) [rad] and
    ``axes_fitted``; ``targets`` [m, P]; the fit: ``sigma``, ``tracker_noise``, ``scatter``,
    ``fit_statistic``, ``fit_dof``, ``fit_z``, ``worst`` stations, ``rms_before``, ``rms_after``,
    ``max_after`` [m], ``residuals`` (K, 3) [m, B]; ``fits`` (both senses), ``cost_ratio``,
    ``sign_separation``, ``condition``, ``undetermined``; ``cross_validation`` and ``accuracy`` (dicts,
    [m]).
    """
    return Result(_core._identify(model, motor, points, targets, calibration, lead_effect, axes, tracker_noise,
                                  folds, accuracy_poses))


def corrected_config(config, corrected: Model, header: str = "") -> str:
    """The configuration ``config`` (YAML text, a path, or None for the seed) with its platform replaced by
    ``corrected`` (an identification's ``corrected_model``) in the legs form, the drives' reference
    recorded, every other key kept (platform_yaml.hpp): what ``hexatwist identify`` writes."""
    return _core._corrected_config(config, corrected, header)


def platform_motion(poses, pose_rates, pose_accelerations) -> Result:
    """The platform's velocity and acceleration (mechanism.hpp, platform_motion) from (N, 6) poses [m, rad]
    and their time derivatives [m/s, rad/s] and [m/s^2, rad/s^2]: w = E(rpy) rpy', w' = E rpy'' + E' rpy'.
    Returns (N, 6) ``velocity`` = [v of the pivot [m/s]; w [rad/s]] and ``acceleration`` [m/s^2; rad/s^2],
    both in the base frame B: the ``velocity`` that :func:`mass_matrix`, :func:`forward_dynamics` and the
    energies take.
    """
    return Result(_core._platform_motion(poses, pose_rates, pose_accelerations))


def inverse_dynamics(config, poses, pose_rates, pose_accelerations) -> Result:
    """Motor torques of the whole mechanism (mechanism.hpp, inverse_dynamics) for (N, 6) poses [m, rad] with
    their time derivatives ``pose_rates`` [m/s, rad/s] and ``pose_accelerations`` [m/s^2, rad/s^2] (of x, y, z,
    roll, pitch, yaw; the library's platform_motion turns them into [v of the pivot; w] in B).

    ``config``: a :class:`Rig`, YAML text, a path, or None (the seed). Returns (N, 6) arrays: ``torque`` [N m]
    (positive lengthens the leg), motor ``angle`` from home [rad], ``speed`` [rad/s], ``acceleration``
    [rad/s^2], ``power`` = torque * speed [W] (negative: the load drives the motor); the torque's parts, which
    add up to it (to rounding), ``gravity``, ``platform_inertia``, ``velocity_product``, ``legs``, ``drives``,
    ``friction`` [N m]; ``screw_force`` axial force in the nut, tension positive [N]; ``thread_speed`` the nut's
    sliding along the screw as a motor speed, real length rate / motor gain [rad/s], and ``thread_dissipation``
    the power the screw's efficiency loses in the thread (>= 0) [W]; and ``status`` (N,) int8 (NaN rows unless
    ok; limits are not checked). Batch like :func:`commands`: GIL released, threads.
    """
    return Result(_core._inverse_dynamics(config, poses, pose_rates, pose_accelerations))


def size_motors(config=None, trajectory=None, *, times=None, poses=None, dt=None, t0: float = 0.0,
                envelope_points: int = 64) -> Result:
    """Motor sizing along a trajectory (motor_sizing.hpp, size_motors), as ``hexatwist dynamics`` does.

    The trajectory: ``trajectory`` a CSV file or text (t, x, y, z, roll, pitch, yaw with unit suffixes, see the
    CLI) resampled at the control period; or ``poses`` (T, 6) [m, rad] with ``times`` (T,) [s] (resampled
    alike), or with a fixed period ``dt`` [s] (default: the control period) from ``t0`` [s]. Rates and
    accelerations are central differences of the poses. Returns per sample: ``time`` (T,) [s], ``poses``
    (T, 6) [m, rad] (the trajectory sized), ``torque`` [N m], ``speed`` [rad/s], ``power`` [W] and the
    torque's parts (``TORQUE_TERMS``: gravity ... friction) [N m], each (T, 6); ``summary``: status (a pose
    limit or numerical failure at ``failed_index`` / ``failed_time``, limit_leg/value/bound), ``envelope``
    "ok" | "exceeded", ``first_violation`` (None or check, leg 0-based, index, time [s], value, bound) and
    ``motors``, six dicts of peak_torque [N m], rms_torque, peak_speed [rad/s], peak_power [W], their times
    [s], energy_driven / energy_regenerated [J], ``share`` per term (RMS of the term / RMS torque), usages
    (peak_usage, speed_usage, rms_usage [-]) and its own ``violation``; ``figure``: the torque-speed figure's
    data: ``operating`` (six dicts of speed [rad/s], torque [N m]), the closed peak ``envelope``,
    ``continuous_torque`` [N m], ``max_speed`` [rad/s].
    """
    return Result(_core._size_motors(config, trajectory, times, poses, dt, t0, envelope_points))


def forward_kinematics_tracked(model: Model, lengths, kind: str = "motor", start=None, max_iterations: int = 30,
                               tolerance: float = 1e-12) -> Result:
    """Forward kinematics along a motion with one :class:`FkTracker` (forward.hpp, forward_kinematics_tracked):
    rows of ``lengths`` (N, 6) [m] solved in order, each from the last solution, ok only on the start's
    assembly mode and away from a platform singularity. ``start``: None (home) or a pose [m, rad]. Returns
    ``poses`` (N, 6) [m, rad] (NaN unless ok), ``status`` (N,) int8, ``iterations``, ``residual`` [m],
    ``condition`` and ``det_sign`` [-].
    """
    return Result(FkTracker(model, kind, start).track(lengths, max_iterations, tolerance))


def register_points(points_T, points_B, max_condition: float = 1e4) -> Result:
    """Best-fit rigid transform X_BT (registration.hpp, Kabsch/Umeyama, no scale) mapping points measured in
    the tracker frame ``points_T`` (N, 3) [m, T] onto the same points ``points_B`` (N, 3) [m, B]:
    p_B ~ R_BT p_T + t_BT. Returns ``status`` (ok, too_few_points, degenerate_registration), ``R_BT`` (3, 3),
    ``t_BT`` (3,) [m, B], ``count``, ``rms_residual``, ``max_residual`` [m], ``max_residual_index``, ``sigma``
    noise per coordinate [m], ``singular_values`` (3,) [m^2], ``reflection`` (bool), ``condition`` [-].
    """
    return Result(_core._register_points(points_T, points_B, max_condition))


def axis_range(model: Model, coordinate, strategy: str = "compensated", **options) -> Result:
    """Reach along one pose coordinate alone, the others at home (workspace.hpp, axis_range): ``coordinate``
    "x", "y", "z", "roll", "pitch", "yaw" or 0..5. Returns ``lower`` <= 0 <= ``upper`` [m or rad] inside every
    limit for the commands of ``strategy``, and ``lower_limit`` / ``upper_limit`` (status, leg 0-based, value,
    bound) met just beyond (status ok: the search bound). ``options``: linear_step [m], angular_step [rad],
    linear_bound [m], angular_bound [rad], tolerance [m or rad]. Raises StatusError when home is outside a limit.
    """
    return Result(_core._axis_range(model, coordinate, strategy, **options))


# ---- design: workspace, U-joint axes, tolerances (docs/theory/design.md §16-19) -------------------


def _workspace_spec(workspace):
    """The required workspace's settings (dict keys tests, test_samples, random, linear [m], angular
    [rad], seed), defaults filled in."""
    spec = dict(tests=True, test_samples=41, random=2000, linear=0.25, angular=float(np.radians(15.0)), seed=1)
    unknown = set(workspace or {}) - set(spec)
    if unknown:
        raise InputError(f"workspace: unknown key(s) {', '.join(sorted(unknown))}; expected {', '.join(spec)}")
    spec.update(workspace or {})
    return dict(tests=bool(spec["tests"]), test_samples=int(spec["test_samples"]), random=int(spec["random"]),
                linear=float(spec["linear"]), angular=float(spec["angular"]), seed=int(spec["seed"]))


def required_workspace(config=None, *, strategy: str = "compensated", **workspace) -> Result:
    """The poses a platform must reach (required_workspace.hpp): the study's four tests at their
    amplitudes (``tests``, ``test_samples`` poses each) and ``random`` combined poses uniform in
    +-``linear`` [m] and +-``angular`` [rad] (``seed``), kept where the platform reaches them.
    ``config``: a Model, a Rig, YAML text, a path or None (the seed; the tests come from its study
    section). Returns ``poses`` (N, 6) [m, rad], ``test_poses``, ``tests_dropped``, ``random_drawn``,
    ``random_reached``."""
    w = _workspace_spec(workspace)
    return Result(_core._required_workspace(config, w["tests"], w["test_samples"], w["random"], w["linear"],
                                            w["angular"], w["seed"], strategy))


def workspace_volume(model: Model, orientation=(0.0, 0.0, 0.0), *, cell: float = 0.0, refine: int = 3,
                     step: float = 0.005, tolerance: float = 1e-9, strategy: str = "compensated", client=None,
                     chunk: int | None = None) -> Result:
    """Volume of the constant-orientation workspace at ``orientation`` (roll, pitch, yaw [rad]) inside
    every limit (workspace_volume.hpp): z columns searched (``step`` [m], bisected to ``tolerance``)
    over an x-y grid of ``cell`` [m] (0: the bounds' larger side / 64) refined ``refine`` times across
    the shadow's edge. Returns ``volume`` [m^3], ``error`` (its difference to the grid twice as coarse:
    the stated error) [m^3], ``coarse_volume``, ``columns`` and ``grid``. With a dask ``client`` the
    cells are computed on the workers (``chunk`` cells a task) and only their sums come back: the same
    numbers, bit for bit."""
    if client is not None:
        return Result(_distributed.workspace_volume_on(client, model, orientation, cell, refine, step, tolerance,
                                                       strategy, chunk))
    return Result(_core._workspace_volume(model, orientation, cell, refine, step, tolerance, strategy,
                                          get_num_threads()))


def workspace_slice(model: Model, orientation=(0.0, 0.0, 0.0), plane: str = "xy", offset: float = 0.0,
                    spacing: float = 0.01, *, step: float = 0.005, tolerance: float = 1e-9,
                    strategy: str = "compensated") -> Result:
    """The boundary of a slice of the constant-orientation workspace (workspace_boundary.hpp):
    ``plane`` "xy" (at z = ``offset`` [m]), "xz" (y = offset) or "yz" (x = offset), searched along
    lines ``spacing`` [m] apart both ways. Per boundary point: ``u``, ``v`` in-plane [m], ``inside``
    and ``outside`` (K, 3) positions [m, B] at most ``tolerance`` apart, the limit the outside one
    breaks (``status`` int8, ``leg`` 0-based, ``value``, ``bound``), ``along`` (0: a line along u);
    ``area`` [m^2] and ``extent`` (u0, u1, v0, v1) searched."""
    return Result(_core._workspace_slice(model, orientation, plane, offset, spacing, step, tolerance, strategy))


def orientation_workspace(model: Model, position=(0.0, 0.0, 0.0), torsions=(0.0,), directions: int = 72, *,
                          step: float = float(np.radians(0.5)), max_tilt: float = float(np.radians(90.0)),
                          tolerance: float = 1e-9, strategy: str = "compensated") -> Result:
    """The orientation workspace at ``position`` [m] (workspace_boundary.hpp): for each torsion [rad]
    (the yaw at zero tilt) and each of ``directions`` azimuths, the largest tilt [rad] with every
    smaller one inside every limit (tilt-and-torsion angles, :func:`tilt_torsion_rotation`). Returns
    ``azimuth`` (D,), ``torsion`` (T,), ``tilt`` (T, D) [rad] (NaN: the torsion alone is refused) and
    the limit met just beyond: ``status``, ``leg``, ``value``, ``bound`` (T, D)."""
    return Result(_core._orientation_workspace(model, position, [float(t) for t in torsions], directions, step,
                                               max_tilt, tolerance, strategy))


def workspace_map(model: Model, orientation=(0.0, 0.0, 0.0), plane: str = "xy", offset: float = 0.0,
                  spacing: float = 0.02, *, grid: dict | None = None, step: float = 0.005, tolerance: float = 1e-9,
                  strategy: str = "compensated", client=None, chunk: int | None = None) -> Result:
    """Maps over a slice (workspace_map.hpp) on a grid ``spacing`` [m] apart around the slice's
    boundary (or ``grid``: plane, offset, u0, u1, nu, v0, v1, nv): per node (nv, nu) the ``status``
    and ``limit_leg`` of its pose, and inside the workspace (NaN outside) ``max_twist`` [rad] and
    ``twist_leg``, ``max_length_error`` [m] and ``length_error_leg``, the Jacobian's ``condition``
    [-], the ``margin`` to the nearest limit (share of its range left) with ``nearest_status`` and
    ``nearest_leg``; ``u`` (nu,), ``v`` (nv,) [m] and ``grid``. With a dask ``client`` the rows are
    computed on the workers (``chunk`` rows a task): the same arrays, bit for bit."""
    if client is not None:
        return Result(_distributed.workspace_map_on(client, model, orientation, plane, offset, spacing, grid, step,
                                                    tolerance, strategy, chunk))
    if grid is None:
        grid = _core._map_grid(model, orientation, plane, offset, spacing, step, tolerance, strategy)
    r = Result(_core._workspace_map_rows(model, orientation, grid, strategy, 0, grid["nv"]))
    return _map_result(r, grid)


def _map_result(r, grid):
    r["grid"] = dict(grid)
    r["u"] = np.linspace(grid["u0"], grid["u1"], grid["nu"])
    r["v"] = np.linspace(grid["v0"], grid["v1"], grid["nv"])
    return r


def design_axes(config=None, poses=None, *, objective: str = "twist", symmetry: str = "symmetric",
                tilt: bool = False, max_tilt: float = float(np.radians(30.0)), grid_step: float = float(np.radians(5.0)),
                fine_step: float = float(np.radians(0.05)), clearance: float = 0.0, max_volume_loss: float = 0.05,
                volume_orientation=(0.0, 0.0, 0.0), cell: float = 0.0, volume_samples: int = 4000, seed: int = 1,
                **workspace) -> Result:
    """The fixed U-joint axes that minimise ``objective`` ("twist" [rad], "length_error" [m] or
    "lead_sensitivity" [m per unit relative lead error]) over the required workspace (``poses`` (N, 6),
    or the :func:`required_workspace` settings in ``workspace``), every limit kept at each of its poses
    and the volume at ``volume_orientation`` within ``max_volume_loss`` (axis_design.hpp).
    ``symmetry``: "symmetric" (odd legs turn +a, even legs -a), "threefold" or "per_leg"; ``tilt``
    also searches tilts out of the joint planes. Returns the turns (6,) [rad] ``turn_base``,
    ``turn_platform``, ``tilt_base``, ``tilt_platform``; ``before`` and ``after`` (largest twist,
    length error and lead sensitivity, each limit's ``margins``, ``volume``); ``objective_before``,
    ``objective_after``; the designed ``model``; and ``yaml``, the configuration with the new axes
    (None when ``config`` is a Model)."""
    w = _workspace_spec(workspace)
    return Result(_core._design_axes(config, poses, w, objective, symmetry, tilt, max_tilt, grid_step, fine_step,
                                     clearance, max_volume_loss, volume_orientation, cell, volume_samples, seed,
                                     get_num_threads()))


def tolerance(config=None, poses=None, *, platforms: int = 1000, seed: int = 1, sigmas: dict | None = None,
              calibration: str = "none", tracker: dict | None = None, linear_worst: bool = True, client=None,
              chunk: int | None = None, **workspace) -> Result:
    """Tolerance analysis (tolerance.hpp): ``platforms`` platforms with manufacturing errors
    (``sigmas``: base_joint, platform_joint [m per coordinate], base_axis, platform_axis [rad], lead
    [relative], offset [m]; per leg), each driven by the compensated commands of its controller (the
    nominal model; ``calibration="perfect"``: one that knows the real platform; ``"stations:N[,SEED]"``
    or ``"plan"``: the configuration identify finds from a simulated tracker log of that platform at N
    random stations or at ``tracker["stations"]``, (K, 6) [m, rad from home], errors then in the frames
    the tracker sees; ``tracker``: ``noise`` [m per coordinate, default 10e-6], ``points_per_station``
    [default 50], ``frames`` "tracker" or "joints") over the required workspace (``poses``, or the :func:`required_workspace` settings in ``workspace``). Returns per
    platform ``max_point``, ``rms_point``, ``max_position`` [m], ``max_orientation`` [rad],
    ``max_point_linear`` (the linear model, same errors; after a tracker calibration from the
    identification's covariance and the sample's own tracker noise), ``failures`` and ``calibration``
    (each platform's calibration status); the pooled histograms
    ``histogram_point`` ...; ``linear`` (the covariance answer: median and p95 of the point, position
    and orientation errors); and ``summary``: Monte Carlo and linearised quantiles side by side. With
    a dask ``client`` the platforms are sampled and evaluated on the workers (``chunk`` platforms a
    task, poses generated there) and only their summaries come back: the same numbers, bit for bit."""
    w = _workspace_spec(workspace)
    sig = {k: float(v) for k, v in (sigmas or {}).items()}
    if client is not None:
        chunk_result, linear = _distributed.tolerance_on(client, config, poses, w, sig, int(seed), int(platforms),
                                                         calibration, bool(linear_worst), chunk, tracker=tracker)
    else:
        threads = get_num_threads()
        chunk_result = _core._tolerance_chunk(config, poses, w, sig, int(seed), 0, int(platforms), calibration,
                                              bool(linear_worst), threads, tracker)
        linear = _core._tolerance_linear(config, poses, w, sig, threads, calibration, tracker, int(seed))
    r = Result(chunk_result)
    r["linear"] = linear
    r["summary"] = _core._tolerance_summary(chunk_result, linear["poses"], linear)
    return r
