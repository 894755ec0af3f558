# SPDX-License-Identifier: BSD-3-Clause
"""The package's conventions (issue 24): a leg is the same number (1 to 6, 0 for none) in every result,
every message and the command line, and it is the column ``leg - 1`` of the per-leg arrays; a Rig is
built once and gives what its YAML gives; Model.from_arrays takes what Model has."""
import json
import subprocess

import numpy as np
import pytest

import hexatwist
from conftest import random_poses, tool


@pytest.fixture(scope="module")
def stiff(model):
    """The seed with a Jacobian condition limit of 9.5 (8.9 at home): a limit of the whole platform."""
    limits = dict(model.limits, jacobian_condition_max=9.5)
    return hexatwist.Model.from_arrays(model.base, model.platform, model.base_axes, model.platform_axes,
                                       model.home_height, lead=model.lead, observation_point=model.observation_point,
                                       **limits)


@pytest.fixture(scope="module")
def refused(stiff):
    """Seeded poses outside some limit: each leg's stroke and bend, and the platform Jacobian's condition."""
    q = np.vstack([random_poses(10_000, seed=21, translation=0.45, rotation=0.5), random_poses(10_000, seed=22)])
    return q[~hexatwist.commands(stiff, q).ok]


def test_a_leg_number_is_the_column_of_its_leg(stiff, refused):
    c = hexatwist.commands(stiff, refused)
    ik = hexatwist.inverse_kinematics(stiff, refused)
    assert set(np.unique(c.limit_leg)) == set(range(7))  # every leg, and 0: the Jacobian's condition
    stroke = np.isin(c.status, [hexatwist.Status.STROKE_ABOVE_MAX, hexatwist.Status.STROKE_BELOW_MIN])
    rows = np.flatnonzero(stroke)
    assert len(rows) > 100
    # The value of a stroke limit is the length of the leg it names, column leg - 1: the joint-to-joint
    # length, or the motor-side command the stroke checks too (IK - offset - twist_gain * twist).
    column = c.limit_leg[rows] - 1
    motor = ik.lengths - stiff.length_offsets - stiff.twist_gain * hexatwist.twist(stiff, refused).twist
    value = c.limit_value[rows]
    geometric = value == ik.lengths[rows, column]
    assert geometric.mean() > 0.9
    np.testing.assert_allclose(value[~geometric], motor[rows, column][~geometric], rtol=0, atol=1e-12)
    bend = np.flatnonzero(c.status == hexatwist.Status.BEND_PLATFORM)
    assert len(bend) > 100
    np.testing.assert_array_equal(c.limit_value[bend], ik.bend_platform[bend, c.limit_leg[bend] - 1])
    condition = c.limit_leg == 0
    assert condition.sum() > 100 and (c.status[condition] == hexatwist.Status.PLATFORM_SINGULARITY).all()


def test_a_leg_is_the_same_number_in_messages_and_the_command_line(stiff, refused, tmp_path):
    cli = tool("HEXATWIST_CLI")
    config = tmp_path / "stiff.yaml"
    config.write_text(stiff.to_yaml())
    c = hexatwist.commands(stiff, refused)
    seen = set()
    for i in range(len(refused)):
        leg = int(c.limit_leg[i])
        if leg in seen:
            continue
        seen.add(leg)
        q = refused[i]
        with pytest.raises(hexatwist.StatusError) as e:
            hexatwist.motor_command(stiff, q)
        message = str(e.value)
        assert (f"leg {leg}:" in message) == (leg > 0) and ("leg " in message) == (leg > 0), message
        # The command line reads the pose in degrees: the same doubles from short decimal text.
        text = ",".join(repr(float(v)) for v in (*q[:3], *np.rad2deg(q[3:])))
        pose = np.array([*q[:3], *np.deg2rad(np.array([float(t) for t in text.split(",")[3:]]))])
        again = hexatwist.commands(stiff, pose)
        out = subprocess.run([cli, "ik", "--config", str(config), "--json", f"--pose={text}"], capture_output=True,
                             text=True, timeout=30)
        j = json.loads(out.stdout)
        assert j["status"] == hexatwist.STATUS_NAMES[again.status], text
        assert j["limit"].get("leg", 0) == again.limit_leg, text
        # One wording of a limit (describe(LimitReport) in the library), Python's and the CLI's.
        assert j["limit"]["message"] in message, (message, j["limit"]["message"])
    assert seen == set(range(7))


def test_the_stream_and_the_simulation_name_the_leg_commands_name(model):
    rig = hexatwist.Rig()
    far = np.array([0.0, 0.3, 0.0, 0.0, 0.0, 0.6])  # beyond one leg's stroke
    expected = hexatwist.commands(model, far)
    assert expected.status != 0 and expected.limit_leg > 0
    stream = hexatwist.Stream(model)
    stream.start(np.zeros(6))
    answer = stream.pose(far)
    assert (answer.status, answer.leg) == (hexatwist.STATUS_NAMES[expected.status], expected.limit_leg)
    q = np.zeros((40, 6))
    q[20:] = far
    for run in (hexatwist.simulate(rig, poses=q), hexatwist.study(rig, poses=q)):
        s = run.summary
        assert (s.status, s.index, s.leg) == (answer.status, 20, answer.leg)
    sized = hexatwist.size_motors(rig, poses=q).summary
    assert (sized.status, sized.limit_leg) == (answer.status, answer.leg)


def test_the_design_functions_number_legs_as_commands_do(model):
    m = hexatwist.workspace_map(model, (0, 0, 0.3), spacing=0.05)
    uu, vv = np.meshgrid(m.u, m.v)
    poses = np.column_stack([uu.ravel(), vv.ravel(), np.zeros(uu.size), np.zeros(uu.size), np.zeros(uu.size),
                             np.full(uu.size, 0.3)])
    c = hexatwist.commands(model, poses)
    np.testing.assert_array_equal(m.limit_leg.ravel(), c.limit_leg)
    ok = c.ok
    twist = np.abs(hexatwist.twist(model, poses[ok]).twist)
    np.testing.assert_array_equal(m.twist_leg.ravel()[ok], twist.argmax(axis=1) + 1)
    assert (m.twist_leg.ravel()[~ok] == 0).all()  # outside: no twist, no leg
    r = hexatwist.axis_range(model, "y")
    beyond = np.zeros(6)
    beyond[1] = r.upper + 1e-6
    assert hexatwist.commands(model, beyond).limit_leg == r.upper_limit.leg > 0
    o = hexatwist.orientation_workspace(model, torsions=(0.0,), directions=8)
    for j, azimuth in enumerate(o.azimuth):
        R = hexatwist.tilt_torsion_rotation(azimuth, o.tilt[0, j] + 1e-8, 0.0)
        rpy = [np.arctan2(R[2, 1], R[2, 2]), np.arcsin(-R[2, 0]), np.arctan2(R[1, 0], R[0, 0])]
        assert hexatwist.commands(model, np.array([0, 0, 0, *rpy])).limit_leg == o.leg[0, j]


def test_a_designs_twist_leg_is_the_leg_of_its_largest_twist():
    rig = hexatwist.Rig()
    w = hexatwist.required_workspace(rig, random=50, test_samples=5)
    d = hexatwist.design_axes(rig, w.poses, volume_samples=100, cell=0.1, grid_step=0.3)
    # The poses a design evaluates: home, then the given ones the nominal platform reaches.
    evaluated = np.vstack([np.zeros(6), w.poses[hexatwist.commands(rig.model, w.poses).ok]])
    assert d.before.poses == len(evaluated)
    for evaluation, model in ((d.before, rig.model), (d.after, d.model)):
        # Legs of a pair may tie to the last bits: the leg named has the largest twist of the pose.
        t = np.abs(hexatwist.twist(model, evaluated[evaluation.twist_pose]).twist)
        assert evaluation.max_twist == pytest.approx(t.max(), rel=1e-12)
        assert t[evaluation.twist_leg - 1] == pytest.approx(t.max(), rel=1e-12), (evaluation.twist_leg, t)


def test_a_rig_is_built_once_and_its_text_gives_the_same(tmp_path):
    text = hexatwist.seed_config_yaml().replace("mass: 1500", "mass: 1800", 1)
    path = tmp_path / "heavy.yaml"
    path.write_text(text)
    rig = hexatwist.Rig(path)
    q = np.zeros((3, 6))
    q[:, 2] = [0.0, 0.05, 0.1]
    for other in (text, str(path), path):  # built for the call: the same numbers
        np.testing.assert_array_equal(hexatwist.inverse_dynamics(other, q, q, q).torque,
                                      hexatwist.inverse_dynamics(rig, q, q, q).torque)
        assert hexatwist.mass_matrix(other, q[1]).tobytes() == hexatwist.mass_matrix(rig, q[1]).tobytes()
    assert hexatwist.corrected_config(rig, rig.model) == hexatwist.corrected_config(path, rig.model)
    with pytest.raises(hexatwist.InputError, match="rig: expected a Rig"):
        hexatwist.inverse_dynamics(rig.model, q, q, q)  # a Model is not a Rig: no drives, no load


def test_from_arrays_takes_one_hand_or_six_and_model_gives_them_back(model):
    hands = ("right", "left", "right", "left", "right", "left")
    limits = {k: v for k, v in model.limits.items()}
    m = hexatwist.Model.from_arrays(model.base, model.platform, model.base_axes, model.platform_axes,
                                    model.home_height, lead=model.lead, thread_hand=hands, **limits)
    assert m.thread_hands == hands and model.thread_hands == ("right",) * 6
    # The twist gain is sign * lead / 2 pi: a left hand turns it over, leg by leg.
    sign = np.where(np.array(hands) == "right", 1.0, -1.0)
    np.testing.assert_array_equal(m.twist_gain, sign * model.twist_gain)
    q = random_poses(200, seed=3, translation=0.1, rotation=0.1)
    np.testing.assert_allclose(hexatwist.twist(m, q).length_error, hexatwist.twist(model, q).length_error * sign,
                               rtol=0, atol=1e-15)
    with pytest.raises(hexatwist.InputError, match="thread_hand"):
        hexatwist.Model.from_arrays(model.base, model.platform, model.base_axes, model.platform_axes, 1.5,
                                    thread_hand=("right",) * 5, **limits)
    with pytest.raises(TypeError):  # the limits are keyword-only: no silent shift of a positional argument
        hexatwist.Model.from_arrays(model.base, model.platform, model.base_axes, model.platform_axes, 1.5, 0.01,
                                    "right", "base", 0.0, 1.4, 2.45, 0.7, 0.08)


def test_the_version_is_the_clis():
    cli = tool("HEXATWIST_CLI")
    out = subprocess.run([cli, "--version"], capture_output=True, text=True, timeout=30, check=True)
    assert out.stdout == f"hexatwist {hexatwist.__version__}\n"
    assert all(part.isdigit() for part in hexatwist.__version__.split(".")) and hexatwist.__version__.count(".") == 2
