# SPDX-License-Identifier: BSD-3-Clause
"""Design (the library's design subsystem, docs/theory/design.md §16-19): the constant-orientation
workspace (volume, slices, maps) and the orientation workspace of a :class:`~hexatwist.Model`; the
required workspace, the design of the fixed U-joint axes and the tolerance study, which take a Model
or a :class:`~hexatwist.Rig` (whose study section gives the tests; YAML text, a path or None for the
seed are accepted too). With a Dask ``client`` the volume, the map and the tolerance study run on
the workers and equal the local run bit for bit. Orientations are (roll, pitch, yaw) [rad]; every
``leg`` field and array holds leg numbers 1 to 6 (0: none, or the whole platform).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, Mapping, Sequence, Union

import numpy as np
import numpy.typing as npt

from . import _hexatwist as _core
from . import distributed as _distributed
from ._hexatwist import HISTOGRAM_BINS, Model
from .core import ArrayLike, FloatArray, Int8Array, PerPose, Result, _fields, _per_leg, get_num_threads
from .dynamics import RigLike
from .kinematics import LimitReport, Strategy

__all__ = [
    "HISTOGRAM_BINS", "PlatformLike", "required_workspace", "workspace_volume", "workspace_slice",
    "orientation_workspace", "tilt_torsion_rotation", "workspace_map", "design_axes", "tolerance",
    "RequiredWorkspace", "VolumeGrid", "WorkspaceVolume", "WorkspaceSlice", "OrientationWorkspace", "TiltExtremes",
    "MapGrid", "WorkspaceMap", "MapSummary", "LimitMargin", "Margins", "DesignEvaluation", "AxisDesign", "Quantiles", "LinearTolerance",
    "ToleranceSummary", "Tolerance", "TargetLayout", "target_layouts",
]

PlatformLike = Union[Model, RigLike]
"""A Model (its geometry; the seed's study tests), or a Rig or what builds one (its model and its study)."""


@dataclass(frozen=True)
class RequiredWorkspace(Result):
    """The poses a platform must reach (required_workspace.hpp)."""

    poses: FloatArray
    """(N, 6) [m, rad]: the tests' first, then the random ones."""
    test_poses: int
    """Of which from the tests."""
    tests_dropped: int
    """Test poses the platform does not reach (left out)."""
    random_drawn: int
    random_reached: int
    """Random poses reached (kept)."""


@dataclass(frozen=True)
class VolumeGrid(Result):
    """The x-y grid of a volume computation."""

    orientation: FloatArray
    """(3,) roll, pitch, yaw [rad]."""
    box_lower: FloatArray
    """(3,) the bounds' box [m, B]."""
    box_upper: FloatArray
    cell: float
    """[m]"""
    refine: int
    x0: float
    y0: float
    nx: int
    ny: int
    cells: int


@dataclass(frozen=True)
class WorkspaceVolume(Result):
    """Volume of the constant-orientation workspace (workspace_volume.hpp)."""

    volume: float
    """[m^3]"""
    coarse_volume: float
    """On the grid twice as coarse [m^3]."""
    error: float
    """The stated error: the difference of the two [m^3]."""
    columns: int
    """z columns searched."""
    grid: VolumeGrid


@dataclass(frozen=True)
class WorkspaceSlice(Result):
    """The boundary of a slice of the constant-orientation workspace, (K,) points."""

    u: FloatArray
    """In-plane coordinates of the inside points [m]."""
    v: FloatArray
    inside: FloatArray
    """(K, 3) last accepted positions [m, B] ..."""
    outside: FloatArray
    """(K, 3) ... within ``tolerance`` of the first refused [m, B]."""
    status: Int8Array
    """The limit each outside point breaks."""
    leg: Int8Array
    """Its leg, 1 to 6 (0: the whole platform)."""
    value: FloatArray
    bound: FloatArray
    along: Int8Array
    """0: found on a line along u, 1: along v."""
    area: float
    """[m^2]"""
    extent: tuple[float, float, float, float]
    """u0, u1, v0, v1 searched [m]."""


@dataclass(frozen=True)
class OrientationWorkspace(Result):
    """The largest tilt towards each azimuth at each torsion (tilt-and-torsion angles)."""

    azimuth: FloatArray
    """(D,) [rad]"""
    torsion: FloatArray
    """(T,) [rad]"""
    tilt: FloatArray
    """(T, D) [rad]; NaN where the torsion alone is refused."""
    status: Int8Array
    """(T, D) the limit met just beyond."""
    leg: Int8Array
    """(T, D) its leg, 1 to 6 (0: the whole platform)."""
    value: FloatArray
    bound: FloatArray

    def extremes(self) -> list[TiltExtremes]:
        """Per torsion, the smallest and largest tilt reached and where (the library's tilt_extremes, as
        ``hexatwist workspace`` prints them)."""
        out = []
        for t in range(len(self.torsion)):
            d = _core._tilt_extremes(self.azimuth, self.tilt[t], self.status[t].astype(int), self.leg[t].astype(int),
                                     self.value[t], self.bound[t])
            out.append(TiltExtremes(torsion=float(self.torsion[t]),
                                    **_fields(d, smallest_limit=LimitReport(**d["smallest_limit"]))))
        return out


@dataclass(frozen=True)
class TiltExtremes(Result):
    """One torsion's extremes of an orientation workspace (:meth:`OrientationWorkspace.extremes`); the
    azimuths where the torsion alone is refused do not count."""

    torsion: float
    """[rad]"""
    reached: int
    """Azimuths where the torsion alone is accepted."""
    smallest: float
    """Smallest of their largest tilts [rad]; NaN when none is reached."""
    smallest_azimuth: float
    """Its azimuth [rad]."""
    smallest_limit: LimitReport
    """What bounds it; when none is reached, what refuses the torsion alone."""
    largest: float
    """Largest tilt reached [rad]."""
    largest_azimuth: float
    """Its azimuth [rad]."""


@dataclass(frozen=True)
class MapGrid(Result):
    """A map's grid: ``nu`` x ``nv`` nodes over [u0, u1] x [v0, v1] in ``plane`` at ``offset``."""

    plane: Literal["xy", "xz", "yz"]
    offset: float
    """[m]"""
    u0: float
    u1: float
    nu: int
    v0: float
    v1: float
    nv: int


@dataclass(frozen=True)
class WorkspaceMap(PerPose):
    """Maps over a slice (workspace_map.hpp), (nv, nu) per node; NaN outside the workspace."""

    status: Int8Array
    """The status of the node's pose."""
    limit_leg: Int8Array
    """The leg (1 to 6) of its limit; 0: none, or the whole platform."""
    max_twist: FloatArray
    """Largest |twist| over the legs [rad]."""
    twist_leg: Int8Array
    """Its leg, 1 to 6."""
    max_length_error: FloatArray
    """Largest |length error| [m]."""
    length_error_leg: Int8Array
    """Its leg, 1 to 6."""
    condition: FloatArray
    """Condition number of the platform Jacobian [-]."""
    margin: FloatArray
    """Share of the nearest limit's range left [-]."""
    nearest_status: Int8Array
    """The nearest limit."""
    nearest_leg: Int8Array
    """Its leg, 1 to 6 (0: the Jacobian's condition)."""
    u: FloatArray
    """(nu,) [m]"""
    v: FloatArray
    """(nv,) [m]"""
    grid: MapGrid

    def summary(self) -> MapSummary:
        """The map's extremes over its nodes inside the workspace (the library's summarize_map, as
        ``hexatwist workspace`` prints them)."""
        def flat(a: Any) -> Any:
            return np.asarray(a).ravel()
        d = _core._map_summary(dict(self.grid), flat(self.status).astype(int), flat(self.max_twist),
                               flat(self.twist_leg).astype(int), flat(self.max_length_error), flat(self.condition),
                               flat(self.margin), flat(self.nearest_status).astype(int),
                               flat(self.nearest_leg).astype(int))
        return MapSummary(**d)


@dataclass(frozen=True)
class MapSummary(Result):
    """A map's extremes over its nodes inside the workspace (:meth:`WorkspaceMap.summary`), each at the
    first node in row order that has it; NaN (positions NaN, legs 0, the limit None) when no node is
    inside (``hexatwist workspace`` writes null)."""

    inside: int
    """Nodes inside the workspace."""
    max_twist: float
    """Largest |twist| [rad]."""
    max_twist_leg: int
    """Its leg, 1 to 6."""
    max_twist_at: FloatArray
    """(3,) its position [m]."""
    max_length_error: float
    """Largest |length error| [m]."""
    max_length_error_at: FloatArray
    """(3,) its position [m]."""
    condition_min: float
    """Smallest condition number of the Jacobian [-]."""
    condition_max: float
    """Largest [-]."""
    margin_min: float
    """Smallest share left to the nearest limit [-]."""
    margin_min_at: FloatArray
    """(3,) its position [m]."""
    margin_min_limit: str | None
    """That limit's status name; None when no node is inside."""
    margin_min_leg: int
    """Its leg, 1 to 6 (0: the Jacobian's condition)."""


@dataclass(frozen=True)
class LimitMargin(Result):
    """The margin to one kind of limit over the required workspace."""

    status: str
    """The limit."""
    leg: int
    """Its leg, 1 to 6 (0: the whole platform)."""
    value: float
    bound: float
    share: float
    """Smallest share of its range left (1 far, 0 on the limit) [-]."""
    pose: int
    """The pose where: an index into the evaluated poses (:class:`DesignEvaluation`)."""


@dataclass(frozen=True)
class Margins(Result):
    """The margins to each kind of limit."""

    stroke: LimitMargin
    command: LimitMargin
    bend: LimitMargin
    singularity: LimitMargin
    condition: LimitMargin


@dataclass(frozen=True)
class DesignEvaluation(Result):
    """A configuration over the required workspace. The poses it evaluates are home, then the required
    poses the nominal platform reaches, in their order: ``twist_pose`` and the margins' ``pose`` index
    that list (0 is home)."""

    poses: int
    """Poses evaluated."""
    reached: int
    """Of which inside every limit."""
    max_twist: float
    """Largest |twist| [rad]."""
    twist_leg: int
    """Its leg, 1 to 6."""
    twist_pose: int
    """Its pose, an index into the evaluated poses (0: home)."""
    max_length_error: float
    """[m]"""
    max_lead_sensitivity: float
    """Largest |dA / d(relative lead error)| [m]."""
    axis_sensitivity: float
    """What U-joint axis errors leave with exact compensation: point A's linearised error, 95th
    percentile over the poses, for 0.1 deg (1 sd) about both normals of every fixed axis [m]."""
    margins: Margins
    volume: float
    """Volume at the design's orientation [m^3]."""
    volume_error: float


@dataclass(frozen=True)
class AxisDesign(Result):
    """The designed fixed U-joint axes (axis_design.hpp)."""

    turn_base: FloatArray
    """(6,) turns of the base axes in their joint planes [rad]."""
    turn_platform: FloatArray
    tilt_base: FloatArray
    """(6,) tilts out of the joint planes [rad]."""
    tilt_platform: FloatArray
    before: DesignEvaluation
    after: DesignEvaluation
    objective: str
    objective_before: float
    """The objective's largest value [rad or m]."""
    objective_after: float
    objective_bound: float
    """No axes of the kind searched (in the joint planes, or tilted up to ``max_tilt``) do better as far
    as the search finds: the worst leg's own best, each leg's axes searched alone with the volume free
    (the legs' twists are independent); NaN for the lead objective, which couples the legs."""
    evaluations: int
    attempts: int
    poses: int
    """Poses of the required workspace."""
    model: Model
    """The designed model."""
    yaml: str | None
    """The configuration with the new axes; None when a Model was given."""


@dataclass(frozen=True)
class Quantiles(Result):
    """Quantiles of an error [m or rad]."""

    median: float
    p95: float
    max: float
    """NaN for the linearised answer."""


@dataclass(frozen=True)
class LinearTolerance(Result):
    """The covariance answer of a tolerance study."""

    point: Quantiles
    position: Quantiles
    orientation: Quantiles
    poses: int


@dataclass(frozen=True)
class ToleranceSummary(Result):
    """A tolerance study's quantiles, Monte Carlo and linearised side by side."""

    platforms: int
    poses: int
    failures: int
    """(platform, pose) pairs without an error (refused, or FK failed)."""
    point: Quantiles
    position: Quantiles
    orientation: Quantiles
    point_linear: Quantiles
    position_linear: Quantiles
    orientation_linear: Quantiles
    worst_point: Quantiles
    """Per platform, the largest point error over the poses."""
    worst_point_linear: Quantiles
    worst_position: Quantiles
    worst_orientation: Quantiles


@dataclass(frozen=True)
class TargetLayout(Result):
    """A layout of targets for a tracker calibration and what it buys (the linearised answer)."""

    extra_targets: FloatArray
    """(N, 3) targets besides point A [m, platform frame]."""
    status: str
    """"ok", or why the plan does not determine the calibration with them."""
    point: Quantiles
    position: Quantiles
    orientation: Quantiles
    """Median and 95th percentile over the poses [m, m, rad]; max is NaN."""


@dataclass(frozen=True)
class Tolerance(Result):
    """A tolerance study (tolerance.hpp): per platform (P,), histograms (HISTOGRAM_BINS,)."""

    max_point: FloatArray
    """Largest error of point A over the poses [m]."""
    rms_point: FloatArray
    max_position: FloatArray
    """[m]"""
    max_orientation: FloatArray
    """[rad]"""
    max_point_linear: FloatArray
    """The linear model's, the same errors [m]."""
    failures: npt.NDArray[np.uint32]
    calibration: npt.NDArray[np.uint8]
    """Each platform's calibration status (0: ok; a tracker calibration that failed: its status code)."""
    histogram_point: npt.NDArray[np.uint64]
    histogram_position: npt.NDArray[np.uint64]
    histogram_orientation: npt.NDArray[np.uint64]
    linear: LinearTolerance
    summary: ToleranceSummary


def _workspace_spec(workspace: Mapping[str, Any]) -> dict[str, Any]:
    """The required workspace's settings (keys tests, test_samples, random, linear [m], angular [rad],
    seed), defaults filled in."""
    spec: dict[str, Any] = dict(_core._required_workspace_defaults())  # the library's RequiredWorkspaceSpec
    unknown = set(workspace) - set(spec)
    if unknown:
        raise _core.InputError(f"workspace: unknown key(s) {', '.join(sorted(unknown))}; expected {', '.join(spec)}")
    spec.update(workspace)
    return dict(tests=bool(spec["tests"]), test_samples=int(spec["test_samples"]), random=int(spec["random"]),
                linear=float(spec["linear"]), angular=float(spec["angular"]), seed=int(spec["seed"]))


def required_workspace(platform: PlatformLike = None, *, strategy: Strategy = "compensated", tests: bool = True,
                       test_samples: int = 41, random: int = 2000, linear: float = 0.25,
                       angular: float = float(np.radians(15.0)), seed: int = 1) -> RequiredWorkspace:
    """The poses a platform must reach (required_workspace.hpp): the study's four tests at their
    amplitudes (``tests``, ``test_samples`` poses each) and ``random`` combined poses uniform in
    +-``linear`` [m] and +-``angular`` [rad] (``seed``), kept where the platform reaches them."""
    return RequiredWorkspace(**_core._required_workspace(platform, tests, test_samples, random, linear, angular, seed,
                                                         strategy))


def _volume(d: dict[str, Any]) -> WorkspaceVolume:
    return WorkspaceVolume(**_fields(d, grid=VolumeGrid(**d["grid"])))


def workspace_volume(model: Model, orientation: ArrayLike = (0.0, 0.0, 0.0), *, cell: float = 0.0, refine: int = 3,
                     step: float = 0.005, tolerance: float = 1e-9, strategy: Strategy = "compensated",
                     client: Any = None, chunk: int | None = None) -> WorkspaceVolume:
    """Volume of the constant-orientation workspace at ``orientation`` inside every limit: z columns
    searched (``step`` [m], bisected to ``tolerance``) over an x-y grid of ``cell`` [m] (0: the bounds'
    larger side / 64) refined ``refine`` times across the shadow's edge; the stated ``error`` is the
    difference to the grid twice as coarse. With a dask ``client`` the cells are computed on the
    workers (``chunk`` cells a task) and only their sums come back."""
    if client is not None:
        return _volume(_distributed._workspace_volume_on(client, model, orientation, cell, refine, step, tolerance,
                                                        strategy, chunk))
    return _volume(_core._workspace_volume(model, orientation, cell, refine, step, tolerance, strategy,
                                           get_num_threads()))


def workspace_slice(model: Model, orientation: ArrayLike = (0.0, 0.0, 0.0), plane: Literal["xy", "xz", "yz"] = "xy",
                    offset: float = 0.0, spacing: float = 0.01, *, step: float = 0.005, tolerance: float = 1e-9,
                    strategy: Strategy = "compensated") -> WorkspaceSlice:
    """The boundary of a slice of the constant-orientation workspace (workspace_boundary.hpp): ``plane``
    "xy" (at z = ``offset`` [m]), "xz" (y = offset) or "yz" (x = offset), searched along lines
    ``spacing`` [m] apart both ways; each boundary point with the limit just outside it."""
    d = _core._workspace_slice(model, orientation, plane, offset, spacing, step, tolerance, strategy)
    return WorkspaceSlice(**_fields(d, extent=tuple(float(x) for x in d["extent"])))


def orientation_workspace(model: Model, position: ArrayLike = (0.0, 0.0, 0.0), torsions: Sequence[float] = (0.0,),
                          directions: int = 72, *, step: float = float(np.radians(0.5)),
                          max_tilt: float = float(np.radians(90.0)), tolerance: float = 1e-9,
                          strategy: Strategy = "compensated") -> OrientationWorkspace:
    """The orientation workspace at ``position`` [m] (workspace_boundary.hpp): for each torsion [rad] (the
    yaw at zero tilt) and each of ``directions`` azimuths, the largest tilt [rad] with every smaller one
    inside every limit (tilt-and-torsion angles, :func:`tilt_torsion_rotation`)."""
    return OrientationWorkspace(**_core._orientation_workspace(model, position, [float(t) for t in torsions],
                                                               directions, step, max_tilt, tolerance, strategy))


def tilt_torsion_rotation(azimuth: float, tilt: float, torsion: float = 0.0) -> FloatArray:
    """Rotation (3, 3) of tilt-and-torsion angles [rad] (Bonev and Ryu): the platform's z axis tilted by
    ``tilt`` towards ``azimuth``, the torsion about it; R = Rz(azimuth) Ry(tilt) Rz(torsion - azimuth)."""
    return _core.tilt_torsion_rotation(azimuth, tilt, torsion)


def _map(rows: Mapping[str, Any], grid: Mapping[str, Any]) -> WorkspaceMap:
    """The typed map of the library's rows (legs as 0-based indices, -1 none) on ``grid``."""
    legs = ("limit_leg", "twist_leg", "length_error_leg", "nearest_leg")
    return WorkspaceMap(**{k: _per_leg(v) if k in legs else v for k, v in rows.items()},
                        u=np.linspace(grid["u0"], grid["u1"], grid["nu"]),
                        v=np.linspace(grid["v0"], grid["v1"], grid["nv"]), grid=MapGrid(**grid))


def workspace_map(model: Model, orientation: ArrayLike = (0.0, 0.0, 0.0), plane: Literal["xy", "xz", "yz"] = "xy",
                  offset: float = 0.0, spacing: float = 0.02, *, grid: Mapping[str, Any] | None = None,
                  step: float = 0.005, tolerance: float = 1e-9, strategy: Strategy = "compensated", client: Any = None,
                  chunk: int | None = None) -> WorkspaceMap:
    """Maps over a slice (workspace_map.hpp) on a grid ``spacing`` [m] apart around the slice's boundary
    (or ``grid``, a :class:`MapGrid`: plane, offset, u0, u1, nu, v0, v1, nv): per node the status of its
    pose and inside the workspace its largest twist and length error, the Jacobian's condition and the
    margin to the nearest limit. With a dask ``client`` the rows are computed on the workers (``chunk``
    rows a task): the same arrays, bit for bit."""
    g = None if grid is None else dict(grid)
    if client is not None:
        rows, g = _distributed._workspace_map_on(client, model, orientation, plane, offset, spacing, g, step, tolerance,
                                                strategy, chunk)
        return _map(rows, g)
    if g is None:
        g = _core._map_grid(model, orientation, plane, offset, spacing, step, tolerance, strategy)
    return _map(_core._workspace_map_rows(model, orientation, g, strategy, 0, g["nv"]), g)


def _evaluation(d: dict[str, Any]) -> DesignEvaluation:
    return DesignEvaluation(**_fields(d, margins=Margins(**{k: LimitMargin(**m) for k, m in d["margins"].items()})))


def design_axes(platform: PlatformLike = None, poses: ArrayLike | None = None, *,
                objective: Literal["twist", "length_error", "lead_sensitivity"] = "twist",
                symmetry: Literal["symmetric", "threefold", "per_leg"] = "symmetric", tilt: bool = False,
                max_tilt: float = float(np.radians(30.0)), grid_step: float = float(np.radians(5.0)),
                fine_step: float = float(np.radians(0.05)), clearance: float = 0.0, max_volume_loss: float = 0.05,
                volume_orientation: ArrayLike = (0.0, 0.0, 0.0), cell: float = 0.0, volume_samples: int = 4000,
                seed: int = 1, **workspace: Any) -> AxisDesign:
    """The fixed U-joint axes that minimise ``objective`` ("twist" [rad], "length_error" [m] or
    "lead_sensitivity" [m per unit relative lead error]) over the required workspace (``poses`` (N, 6),
    or the :func:`required_workspace` settings in ``workspace``), every limit kept at each of its poses
    and the volume at ``volume_orientation`` within ``max_volume_loss`` (axis_design.hpp).
    ``symmetry``: "symmetric" (odd legs turn +a, even legs -a), "threefold" or "per_leg"; ``tilt``
    also searches tilts out of the joint planes."""
    w = _workspace_spec(workspace)
    d = _core._design_axes(platform, poses, w, objective, symmetry, tilt, max_tilt, grid_step, fine_step, clearance,
                           max_volume_loss, volume_orientation, cell, volume_samples, seed, get_num_threads())
    return AxisDesign(**_fields(d, before=_evaluation(d["before"]), after=_evaluation(d["after"])))


def _quantiles(d: Mapping[str, Any]) -> dict[str, Any]:
    return {k: Quantiles(**v) if isinstance(v, dict) else v for k, v in d.items()}


def tolerance(platform: PlatformLike = None, poses: ArrayLike | None = None, *, platforms: int = 1000, seed: int = 1,
              sigmas: Mapping[str, float] | None = None, calibration: str = "none",
              tracker: Mapping[str, Any] | None = None, linear_worst: bool = True, client: Any = None,
              chunk: int | None = None, **workspace: Any) -> Tolerance:
    """Tolerance analysis (tolerance.hpp): ``platforms`` platforms with manufacturing errors (``sigmas``:
    base_joint, platform_joint [m per coordinate], base_axis, platform_axis [rad], lead [relative], offset
    [m]; per leg), each driven by the compensated commands of its controller (the nominal model;
    ``calibration="perfect"``: one that knows the real platform; ``"stations:N[,SEED]"`` or ``"plan"``: the
    configuration identify finds from a simulated tracker log of that platform at N random stations or at
    ``tracker["stations"]``, (K, 6) [m, rad from home], errors then in the frames the tracker sees;
    ``tracker``: ``noise`` [m per coordinate, default 10e-6], ``points_per_station`` [default 50],
    ``frames`` "tracker" or "joints", ``targets`` (N, 3) more targets on the platform besides point A
    [m, platform frame], measured at every station: with them the pivot and the orientation calibrate as
    point A does) over the required workspace (``poses``, or the
    :func:`required_workspace` settings in ``workspace``). ``max_point_linear`` after a tracker calibration
    comes from the identification's covariance and the sample's own tracker noise. With a dask ``client`` the platforms
    are sampled and evaluated on the workers (``chunk`` platforms a task, poses generated there) and
    only their summaries come back: the same numbers, bit for bit."""
    w = _workspace_spec(workspace)
    sig = {k: float(v) for k, v in (sigmas or {}).items()}
    if client is not None:
        chunk_result, linear = _distributed._tolerance_on(client, platform, poses, w, sig, int(seed), int(platforms),
                                                         calibration, bool(linear_worst), chunk,
                                                         tracker=None if tracker is None else dict(tracker))
    else:
        threads = get_num_threads()
        t = None if tracker is None else dict(tracker)
        chunk_result = _core._tolerance_chunk(platform, poses, w, sig, int(seed), 0, int(platforms), calibration,
                                              bool(linear_worst), threads, t)
        linear = _core._tolerance_linear(platform, poses, w, sig, threads, calibration, t, int(seed))
    summary = _core._tolerance_summary(chunk_result, linear["poses"], linear)
    per_platform = {k: v for k, v in chunk_result.items() if k != "first"}
    return Tolerance(**per_platform, linear=LinearTolerance(**_quantiles(linear)),
                     summary=ToleranceSummary(**_quantiles(summary)))


def target_layouts(platform: PlatformLike = None, poses: ArrayLike | None = None, *, max_extra: int = 3,
                   calibration: str = "stations:40", tracker: Mapping[str, Any] | None = None, seed: int = 1,
                   sigmas: Mapping[str, float] | None = None, **workspace: Any) -> list[TargetLayout]:
    """Where to put the targets (tolerance_calibration.hpp ``target_layouts``, ``tolerance --target-layouts``):
    the layouts of point A and 0 to ``max_extra`` more targets evenly spaced on the circle through A about the
    pivot, each calibrated as :func:`tolerance`'s ``calibration`` (a tracker calibration) with ``tracker``'s
    settings, answered by the linear model over the required workspace: the point A, pivot and orientation
    errors' median and 95th percentile. The CLI's numbers."""
    w = _workspace_spec(workspace)
    sig = {k: float(v) for k, v in (sigmas or {}).items()}
    layouts = _core._target_layouts(platform, poses, w, sig, get_num_threads(), calibration,
                                    None if tracker is None else dict(tracker), int(seed), int(max_extra))
    return [TargetLayout(extra_targets=d["extra_targets"], status=d["status"],
                         **{k: Quantiles(**d[k]) for k in ("point", "position", "orientation")}) for d in layouts]
