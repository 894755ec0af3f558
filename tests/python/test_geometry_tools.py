# SPDX-License-Identifier: BSD-3-Clause
"""Registration, forward kinematics along a motion with a tracker, the axis ranges, and the YAML
round trip of angles in degrees: the library called directly (bit for bit) and properties."""
import numpy as np
import pytest

import hexatwist
from test_dynamics import reference


def rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def test_register_points_equals_the_library_and_recovers_the_transform(tmp_path):
    rng = np.random.default_rng(4)
    p_T = rng.uniform(-2, 2, (30, 3))
    R, t = rotation([0.3, -1, 0.5], 0.7), np.array([1.5, -0.4, 2.0])
    p_B = p_T @ R.T + t + rng.normal(0, 1e-5, p_T.shape)
    r = hexatwist.register_points(p_T, p_B)
    ref = reference("registration", np.hstack([p_T, p_B]), tmp_path, None)
    assert r.status == "ok" and ref[0] == 0 and r.count == 30
    assert np.array_equal(r.R_BT.ravel(), ref[1:10]) and np.array_equal(r.t_BT, ref[10:13])
    assert [r.rms_residual, r.max_residual, r.sigma, r.condition] == ref[13:17].tolist()
    np.testing.assert_allclose(r.R_BT, R, atol=1e-5)
    np.testing.assert_allclose(r.t_BT, t, atol=2e-5)
    assert 5e-6 < r.sigma < 2e-5 and not r.reflection
    # Noise-free: exact to rounding; the residual of each point is its distance.
    exact = hexatwist.register_points(p_T, p_T @ R.T + t)
    np.testing.assert_allclose(exact.R_BT, R, atol=1e-13)
    assert exact.rms_residual < 1e-12


def test_register_points_reports_what_it_cannot_determine():
    line = np.outer(np.arange(6.0), [1, 2, 3])
    assert hexatwist.register_points(line, line + 1).status == "degenerate_registration"
    assert hexatwist.register_points(np.eye(3)[:2], np.eye(3)[:2]).status == "too_few_points"
    with pytest.raises(hexatwist.InputError, match="NaN"):
        hexatwist.register_points(np.full((4, 3), np.nan), np.zeros((4, 3)))
    with pytest.raises(hexatwist.InputError, match="as many"):
        hexatwist.register_points(np.zeros((4, 3)), np.zeros((5, 3)))
    with pytest.raises(hexatwist.InputError, match=r"\(N, 3\)"):
        hexatwist.register_points(np.zeros((4, 2)), np.zeros((4, 2)))


def path_poses(n=1500):
    s = np.linspace(0, 1, n)[:, None]
    return np.sin(np.pi * s) * np.array([0.2, -0.1, 0.25, 0.1, -0.15, 0.3])


def test_tracked_fk_equals_the_library_and_follows_the_motion(model, tmp_path):
    q = path_poses()
    m = hexatwist.commands(model, q).commands
    r = hexatwist.forward_kinematics_tracked(model, m)
    ref = reference("tracked", m, tmp_path, 9)
    assert np.array_equal(r.status, ref[:, 6].astype(int)) and (r.status == 0).all()
    assert np.array_equal(r.poses, ref[:, :6]) and np.array_equal(r.iterations, ref[:, 7])
    assert np.array_equal(r.residual, ref[:, 8])
    np.testing.assert_allclose(r.poses, q, atol=1e-9)
    assert np.all(r.det_sign == r.det_sign[0]) and np.all(r.condition < model.limits["jacobian_condition_max"])
    # One tracker fed in two parts gives the same as one call; its state is the last solution.
    tr = hexatwist.FkTracker(model)
    assert not tr.valid and tr.last is None
    a, b = tr.track(m[:700]), tr.track(m[700:])
    assert np.array_equal(np.vstack([a["poses"], b["poses"]]), r.poses)
    assert tr.valid and np.array_equal(tr.last, r.poses[-1]) and tr.det_sign == r.det_sign[0]


def test_tracker_keeps_its_state_on_failure_and_can_be_set(model):
    tr = hexatwist.FkTracker(model, start=[0, 0, 0.1, 0, 0, 0.05])
    assert tr.valid
    np.testing.assert_allclose(tr.last, [0, 0, 0.1, 0, 0, 0.05], atol=1e-15)
    good = hexatwist.motor_command(model, [0, 0, 0.12, 0, 0, 0.05])
    r = tr.track(good)
    assert r["status"] == 0 and r["iterations"] <= 4
    last = tr.last.copy()
    bad = tr.track(np.full(6, 100.0))  # no pose has these lengths
    assert bad["status"] != 0 and np.isnan(bad["poses"]).all()
    assert np.array_equal(tr.last, last)
    geo = hexatwist.FkTracker(model, kind="geometric")
    lengths = hexatwist.inverse_kinematics(model, path_poses(50)).lengths
    np.testing.assert_allclose(geo.track(lengths)["poses"], path_poses(50), atol=1e-9)
    with pytest.raises(hexatwist.InputError, match="kind"):
        hexatwist.FkTracker(model, kind="x")
    with pytest.raises(hexatwist.InputError, match="NaN"):
        hexatwist.FkTracker(model).track(np.full(6, np.nan))


def test_axis_range_equals_the_library_and_bounds_the_accepted_poses(model, tmp_path):
    ref = reference("axis_range", np.zeros(1), tmp_path, 5)
    rows = iter(ref)
    for strategy in ("compensated", "conventional"):
        for k, name in enumerate(hexatwist.COORDINATES):
            r = hexatwist.axis_range(model, name, strategy=strategy)
            lower, upper, sl, su, s = next(rows)
            assert (r.lower, r.upper) == (lower, upper) and s == 0, name
            assert hexatwist.STATUS_NAMES[int(sl)] == r.lower_limit["status"]
            assert hexatwist.STATUS_NAMES[int(su)] == r.upper_limit["status"]
            assert r == hexatwist.axis_range(model, k, strategy=strategy)
            assert r.lower < 0 < r.upper
            # Inside at the ends, outside just beyond (where a limit was met).
            for end, sign, limit in ((r.upper, 1, r.upper_limit), (r.lower, -1, r.lower_limit)):
                q = np.zeros(6)
                q[k] = end
                assert hexatwist.commands(model, q, strategy).status == 0
                if limit["status"] != "ok":
                    q[k] = end + sign * 1e-6
                    assert hexatwist.commands(model, q, strategy).status != 0
    with pytest.raises(hexatwist.InputError, match="coordinate"):
        hexatwist.axis_range(model, "w")
    with pytest.raises(hexatwist.InputError, match="finite"):
        hexatwist.axis_range(model, 0, linear_step=-1.0)


YAML_DEG = """name: degrees
home_height: 1.5
screw: {{lead: 0.01, thread: right, driven_side: base}}
symmetric: {{Ra: 1.2, Rb: 1.5, da: 0.2, db: 0.3, H: 1.511, base_pair_angles_deg: [60.3, -59.7, 181.5],
             platform_pair_angles_deg: [1.5, 240.75, 119.03]}}
limits: {{length_min: 1.4, length_max: 2.45, bend_max_deg: {bend}, singularity_margin_deg: {margin}}}
"""


@pytest.mark.parametrize("bend, margin", [(40, 5), (1.5, 3.0), (0.21, 0.39), (30.03, 2.06), (45.77, 7.93)])
def test_yaml_with_degrees_reloads_to_the_same_model(bend, margin):
    text = YAML_DEG.format(bend=bend, margin=margin).replace("home_height: 1.5\n", "")
    model = hexatwist.load_model(text)
    again = hexatwist.load_model(model.to_yaml())
    assert again.limits == model.limits  # bit for bit: the radians survive the degrees written
    for k in ("base", "platform", "base_axes", "platform_axes", "lead", "length_offsets", "observation_point"):
        assert np.array_equal(getattr(again, k), getattr(model, k)), k
    assert again.to_yaml() == model.to_yaml()
    assert f"bend_max_deg: {bend}\n" in model.to_yaml()  # the shortest text: what the user wrote


def test_mjcf_is_the_library_text(tmp_path):
    import subprocess
    import xml.etree.ElementTree as ET
    from conftest import tool
    text = hexatwist.mjcf()
    dst = tmp_path / "seed.xml"
    subprocess.run([tool("HEXATWIST_REFERENCE"), "mjcf", "-", str(dst)], check=True, timeout=60)
    assert text == dst.read_text()
    root = ET.fromstring(text)
    assert root.tag == "mujoco"
    names = {a.get("name") for a in root.iter("motor")} | {a.get("name") for a in root.iter("general")}
    assert {f"motor{i}" for i in range(1, 7)} <= names
    assert hexatwist.mjcf(hexatwist.Rig()) == text == hexatwist.mjcf(hexatwist.seed_config_yaml())
    no_lead = hexatwist.seed_config_yaml().replace("lead: 0.010", "lead: 0", 1)
    if no_lead != hexatwist.seed_config_yaml():
        with pytest.raises(hexatwist.ConfigError):
            hexatwist.mjcf(no_lead)
