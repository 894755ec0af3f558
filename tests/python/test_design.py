# SPDX-License-Identifier: BSD-3-Clause
"""The design functions from Python (docs/theory/design.md §16-19): the workspace's volume, slices, maps
and orientation workspace against the batch functions, the designed configuration through its YAML,
and the tolerance study's independence from threads."""
import json
import os
import subprocess
import tempfile

import numpy as np
import pytest

import hexatwist
from conftest import tool


def test_volume_from_its_cells_equals_the_whole_computation(model):
    v = hexatwist.workspace_volume(model, cell=0.05)
    core = hexatwist._core
    grid = core._volume_grid(model, (0, 0, 0), 0.05)
    fine, coarse, columns = core._volume_cells(model, grid, 0.005, 1e-9, "compensated", 0, grid["cells"])
    again = core._volume_from_cells(grid, fine, coarse, columns)
    assert again["volume"] == v.volume and again["error"] == v.error
    assert 1.2 < v.volume < 1.35 and v.error < 0.01 * v.volume


def test_slice_points_are_inside_just_inside_and_refused_just_outside(model):
    orientation = np.array([0.05, 0.0, -0.2])
    s = hexatwist.workspace_slice(model, orientation, "xz", 0.1, spacing=0.03)
    assert len(s.u) > 50
    poses = lambda p: np.hstack([p, np.tile(orientation, (len(p), 1))])  # noqa: E731
    inside = hexatwist.commands(model, poses(s.inside))
    outside = hexatwist.commands(model, poses(s.outside))
    assert inside.ok.all()
    assert np.array_equal(outside.status, s.status)
    assert np.array_equal(outside.limit_leg, s.leg)
    assert np.all(np.linalg.norm(s.outside - s.inside, axis=1) <= 1e-9)
    assert np.array_equal(s.u, s.inside[:, 0]) and np.array_equal(s.v, s.inside[:, 2])


def test_map_holds_the_largest_twist_of_each_pose_and_nan_outside(model):
    m = hexatwist.workspace_map(model, (0, 0, 0.1), "xy", 0.05, spacing=0.05)
    uu, vv = np.meshgrid(m.u, m.v)
    poses = np.column_stack([uu.ravel(), vv.ravel(), np.full(uu.size, 0.05), np.zeros(uu.size), np.zeros(uu.size),
                             np.full(uu.size, 0.1)])
    c = hexatwist.commands(model, poses)
    assert np.array_equal(c.status.reshape(uu.shape), m.status)
    t = hexatwist.twist(model, poses)
    ok = c.ok.reshape(uu.shape)
    assert np.array_equal(np.abs(t.twist).max(axis=1).reshape(uu.shape)[ok], m.max_twist[ok])
    assert np.isnan(m.max_twist[~ok]).all() and (m.margin[ok] > 0).all()
    assert ok.sum() > 100 and (~ok).sum() > 20


def test_orientation_workspace_reach_is_accepted_and_the_next_step_refused(model):
    o = hexatwist.orientation_workspace(model, (0, 0, 0.1), torsions=[0.0, 0.3], directions=12)
    for t, torsion in enumerate(o.torsion):
        for j, azimuth in enumerate(o.azimuth):
            rpy = []
            for tilt in (o.tilt[t, j], o.tilt[t, j] + 1e-8):
                R = hexatwist.tilt_torsion_rotation(azimuth, tilt, torsion)
                rpy.append([np.arctan2(R[2, 1], R[2, 2]), np.arcsin(-R[2, 0]), np.arctan2(R[1, 0], R[0, 0])])
            c = hexatwist.commands(model, np.hstack([np.tile([0, 0, 0.1], (2, 1)), rpy]))
            assert c.status[0] == 0 and c.status[1] == o.status[t, j]


def test_map_summary_and_tilt_extremes_are_the_cli_workspace_summary(model):
    # The CLI's summary.json and these come from the library's summarize_map and tilt_extremes: equal
    # to the bit; and against numpy over the arrays.
    out = os.path.join(tempfile.mkdtemp(), "w")
    cli = json.loads(subprocess.run(
        [tool("HEXATWIST_CLI"), "workspace", "--heights", "0", "--spacing", "0.1", "--yaws", "0,80", "--map-height", "0.1",
         "--map-spacing", "0.1", "--cell", "0.1", "--no-figures", "--no-csv", "--out", out, "--json"],
        capture_output=True, text=True, check=True).stdout)
    m = hexatwist.workspace_map(model, (0, 0, 0), "xy", 0.1, spacing=0.1)
    s = m.summary()
    j = cli["map"]
    assert s.inside == j["inside"] and s.max_twist == j["max_twist"] and s.max_twist_leg == j["max_twist_leg"]
    assert list(s.max_twist_at) == j["max_twist_at"] and list(s.margin_min_at) == j["margin_min_at"]
    assert (s.condition_min, s.condition_max, s.margin_min) == (j["condition_min"], j["condition_max"], j["margin_min"])
    assert (s.margin_min_limit, s.margin_min_leg) == (j["margin_min_limit"], j["margin_min_leg"])
    ok = m.status == 0
    assert s.inside == ok.sum() and s.max_twist == m.max_twist[ok].max() and s.condition_min == m.condition[ok].min()
    assert s.max_length_error == m.max_length_error[ok].max() and s.margin_min == m.margin[ok].min()
    # No node inside: NaN and None here, null in the JSON.
    empty = hexatwist.workspace_map(model, (0, 0, 0), "xy", 0.9, spacing=0.2).summary()
    assert empty.inside == 0 and np.isnan(empty.max_twist) and empty.margin_min_limit is None
    assert empty.max_twist_leg == 0 and np.isnan(empty.margin_min_at).all()
    none = json.loads(subprocess.run(
        [tool("HEXATWIST_CLI"), "workspace", "--heights", "0", "--spacing", "0.1", "--yaws", "0", "--map-height", "0.9",
         "--map-spacing", "0.2", "--cell", "0.1", "--no-figures", "--no-csv", "--out", out + "-empty", "--json"],
        capture_output=True, text=True, check=True).stdout)["map"]
    assert none["inside"] == 0 and none["max_twist"] is None and none["margin_min_limit"] is None
    o = hexatwist.orientation_workspace(model, torsions=np.radians([0.0, 80.0]))
    for e, c in zip(o.extremes(), cli["orientation_workspace"]["torsions"]):
        assert e.torsion == c["torsion"] and e.reached == c["reached"]
        assert e.smallest_limit.status == c["smallest_limit"]["status"]
        for mine, key in ((e.smallest, "smallest_tilt"), (e.smallest_azimuth, "smallest_azimuth"),
                          (e.largest, "largest_tilt"), (e.largest_azimuth, "largest_azimuth")):
            assert (np.isnan(mine) and c[key] is None) or mine == c[key]
    assert o.extremes()[0].reached == 72 and o.extremes()[0].smallest == np.nanmin(o.tilt[0])
    assert o.extremes()[1].reached == 0 and o.extremes()[1].smallest_limit.status == "bend_base"


def test_designed_axes_halve_the_twist_and_their_yaml_loads_back(model):
    w = hexatwist.required_workspace(random=600)
    d = hexatwist.design_axes(None, w.poses)
    designed = hexatwist.load_model(d.yaml)
    assert np.allclose(designed.base_axes, d.model.base_axes, rtol=0, atol=0)
    before = np.abs(hexatwist.twist(model, w.poses).twist).max()
    after = np.abs(hexatwist.twist(designed, w.poses).twist).max()
    assert after < 0.5 * before
    assert after == pytest.approx(d.after["max_twist"], abs=1e-12)
    assert hexatwist.commands(designed, w.poses).ok.all()
    assert d.after["volume"] >= 0.95 * d.before["volume"]
    assert set(d.after["margins"]) == {"stroke", "command", "bend", "singularity", "condition"}
    with pytest.raises(hexatwist.InputError, match="objective"):
        hexatwist.design_axes(None, w.poses, objective="speed")


def test_tolerance_does_not_depend_on_threads_and_a_perfect_calibration_leaves_no_error():
    settings = dict(platforms=40, random=60, test_samples=5)
    n = hexatwist.get_num_threads()
    try:
        hexatwist.set_num_threads(1)
        one = hexatwist.tolerance(**settings)
        hexatwist.set_num_threads(2)
        two = hexatwist.tolerance(**settings)
    finally:
        hexatwist.set_num_threads(0)
    assert n >= 1
    for key in ("max_point", "rms_point", "max_point_linear", "histogram_point"):
        assert np.array_equal(one[key], two[key]), key
    perfect = hexatwist.tolerance(calibration="perfect", **settings)
    assert perfect.max_point.max() < 1e-11
    with pytest.raises(hexatwist.InputError, match="sigmas"):
        hexatwist.tolerance(sigmas=dict(joint=1e-5), **settings)
    with pytest.raises(hexatwist.InputError, match="workspace"):
        hexatwist.tolerance(platforms=2, randoms=5)


def test_a_tracker_calibration_leaves_micrometres_and_its_linear_answer_agrees():
    # The seed platform, 40 random stations, 10 um tracker noise, 4 platforms x 76 poses: measured
    # median point error 1.94 um after, 0.275 mm with the nominal controller (142x); per platform MC
    # vs linear within 0.25 %; pooled median MC / linear 1.04.
    settings = dict(platforms=4, random=60, test_samples=5)
    before = hexatwist.tolerance(**settings)
    after = hexatwist.tolerance(calibration="stations:40", tracker=dict(noise=10e-6, points_per_station=50),
                                **settings)
    assert np.all(after.calibration == 0) and after.summary["failures"] == 0
    assert before.summary["point"]["median"] > 50 * after.summary["point"]["median"]
    assert np.allclose(after.max_point_linear, after.max_point, rtol=0.04)
    ratio = after.summary["point"]["median"] / after.linear["point"]["median"]
    assert 0.75 < ratio < 1.33
    # A plan given as its stations: the random plan's own stations give the same study bit for bit.
    plan = np.vstack([np.zeros(6), hexatwist.stations_run(count=40, seed=1).stations, np.zeros(6)])
    same = hexatwist.tolerance(calibration="plan", tracker=dict(stations=plan), **settings)
    assert np.array_equal(same.max_point, after.max_point)
    with pytest.raises(hexatwist.InputError, match=r"\[calibration\]"):
        hexatwist.tolerance(calibration="stations:0", **settings)
    with pytest.raises(hexatwist.InputError, match=r"\[tracker_noise\]"):
        hexatwist.tolerance(calibration="stations:5", tracker=dict(noise=-1.0), **settings)
    with pytest.raises(hexatwist.InputError, match="tracker"):
        hexatwist.tolerance(calibration="stations:5", tracker=dict(nois=1e-5), **settings)


def test_targets_around_the_platform_calibrate_its_orientation_as_the_cli_does():
    # Two more targets on point A's circle (the CLI's layout of 3 targets): the pivot and the
    # orientation an order of magnitude better; the same numbers as `tolerance --targets-mm`.
    settings = dict(platforms=3, random=40, test_samples=5, calibration="stations:20")
    alone = hexatwist.tolerance(**settings)
    targets = np.array([[-0.6, 1.0392304845413265, 0.0], [-0.6, -1.0392304845413265, 0.0]])
    three = hexatwist.tolerance(tracker=dict(targets=targets), **settings)
    assert np.all(three.calibration == 0)
    assert alone.summary["position"]["p95"] > 5 * three.summary["position"]["p95"]
    assert alone.summary["orientation"]["p95"] > 5 * three.summary["orientation"]["p95"]
    cli = json.loads(subprocess.run(
        [tool("HEXATWIST_CLI"), "tolerance", "--platforms", "3", "--workspace", "random=40,samples=5", "--calibration", "stations:20",
         "--targets-mm", ";".join(",".join(repr(1e3 * v) for v in t) for t in targets), "--json", "--no-figures",
         "--no-csv", "--out", os.path.join(tempfile.mkdtemp(), "t")],
        capture_output=True, text=True, check=True).stdout)
    for key in ("point", "position", "orientation"):
        assert cli["monte_carlo"][key]["p95"] == pytest.approx(three.summary[key]["p95"], rel=1e-12)
    # The layouts, as `tolerance --target-layouts 2` prints them: layout 3 is these targets, its linear
    # answer this study's; point A alone is the one-target study's.
    layouts = hexatwist.target_layouts(max_extra=2, calibration="stations:20", random=40, test_samples=5)
    assert [len(l.extra_targets) for l in layouts] == [0, 1, 2]
    assert all(l.status == "ok" for l in layouts)
    assert np.allclose(layouts[2].extra_targets, targets, rtol=0, atol=1e-15)
    assert layouts[2].position.p95 == pytest.approx(three.linear.position.p95, rel=1e-12)
    assert layouts[0].orientation.p95 == pytest.approx(alone.linear.orientation.p95, rel=1e-12)
    layout_cli = json.loads(subprocess.run(
        [tool("HEXATWIST_CLI"), "tolerance", "--platforms", "3", "--workspace", "random=40,samples=5",
         "--calibration", "stations:20", "--target-layouts", "2", "--json", "--no-figures", "--no-csv",
         "--out", os.path.join(tempfile.mkdtemp(), "l")], capture_output=True, text=True, check=True).stdout)
    for mine, theirs in zip(layouts, layout_cli["target_layouts"]):
        assert np.array_equal(mine.extra_targets.reshape(-1, 3), np.array(theirs["extra_targets"]).reshape(-1, 3))
        assert mine.orientation.p95 == theirs["orientation"]["p95"]
    with pytest.raises(hexatwist.InputError, match="tracker calibration"):
        hexatwist.target_layouts(calibration="none", random=40, test_samples=5)
    with pytest.raises(hexatwist.InputError, match=r"\[targets\]"):
        hexatwist.tolerance(tracker=dict(targets=[[1.2, 0.0, 0.0005]]), **settings)
    with pytest.raises(hexatwist.InputError, match="targets must be"):
        hexatwist.tolerance(tracker=dict(targets=[1.0, 2.0]), **settings)


def test_every_public_function_pickles_by_reference():
    # Dask ships functions pickled (client.run(hexatwist.get_num_threads)): a pybind11 function does not pickle.
    import pickle

    import inspect

    functions = [getattr(hexatwist, n) for n in hexatwist.__all__
                 if inspect.isfunction(getattr(hexatwist, n)) or inspect.isbuiltin(getattr(hexatwist, n))]
    assert len(functions) > 40
    for f in functions:
        assert pickle.loads(pickle.dumps(f)) is f, f.__name__
