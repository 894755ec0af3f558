# SPDX-License-Identifier: BSD-3-Clause
"""Dynamics and motor sizing through the bindings: the library called directly (bit for bit), and
properties that break if an argument were swapped (forward dynamics inverts inverse dynamics, the
energies, the torque's parts)."""
import json
import os
import pickle
import subprocess

import numpy as np
import pytest

import hexatwist
from conftest import tool

PARTS = ("torque", "angle", "speed", "acceleration", "power", "gravity", "platform_inertia", "velocity_product",
         "legs", "drives", "friction", "screw_force")


@pytest.fixture(scope="module")
def rig():
    return hexatwist.Rig()


def motions(n, seed=11):
    """n seeded random poses [m, rad] with rates and accelerations of a fast motion simulator."""
    rng = np.random.default_rng(seed)
    q = rng.uniform(-1, 1, (n, 6)) * [0.2, 0.2, 0.2, 0.2, 0.2, 0.2]
    qd = rng.uniform(-1, 1, (n, 6)) * [0.6, 0.6, 0.6, 1.0, 1.0, 1.0]
    qdd = rng.uniform(-1, 1, (n, 6)) * [5.0, 5.0, 5.0, 8.0, 8.0, 8.0]
    return q, qd, qdd


def reference(mode, data, tmp_path, row):
    src, dst = tmp_path / "in.bin", tmp_path / "out.bin"
    if isinstance(data, np.ndarray):
        np.ascontiguousarray(data, dtype=np.float64).tofile(src)
    else:
        src = data
    subprocess.run([tool("HEXATWIST_REFERENCE"), mode, str(src), str(dst)], check=True, timeout=120)
    out = np.fromfile(dst)
    return out if row is None else out.reshape(-1, row)


def test_inverse_dynamics_equals_the_library_bit_for_bit(rig, tmp_path):
    q, qd, qdd = motions(3000)
    ref = reference("dynamics", np.hstack([q, qd, qdd]), tmp_path, 72 + 1 + 36 + 2 + 6)
    r = hexatwist.inverse_dynamics(rig, q, qd, qdd)
    assert np.array_equal(r.status, ref[:, 72].astype(int))
    assert r.ok.all()  # limits are not checked: every random pose has a solution
    for j, name in enumerate(PARTS):
        assert np.array_equal(r[name], ref[:, 6 * j:6 * j + 6], equal_nan=True), name
    # The one-pose calls at the velocity platform_motion gives, for the first 40 good rows.
    m = hexatwist.platform_motion(q, qd, qdd)
    for i in np.flatnonzero(r.ok)[:40]:
        assert np.array_equal(hexatwist.mass_matrix(rig, q[i]), ref[i, 73:109].reshape(6, 6)), i
        assert hexatwist.kinetic_energy(rig, q[i], m.velocity[i]) == ref[i, 109]
        assert hexatwist.potential_energy(rig, q[i]) == ref[i, 110]
        a = hexatwist.forward_dynamics(rig, q[i], m.velocity[i], r.torque[i] - r.friction[i])
        assert np.array_equal(a, ref[i, 111:117]), i


def test_forward_dynamics_inverts_inverse_dynamics(rig):
    q, qd, qdd = motions(200, seed=5)
    r = hexatwist.inverse_dynamics(rig, q, qd, qdd)
    m = hexatwist.platform_motion(q, qd, qdd)
    for i in np.flatnonzero(r.ok)[:60]:
        a = hexatwist.forward_dynamics(rig, q[i], m.velocity[i], r.torque[i] - r.friction[i])
        np.testing.assert_allclose(a, m.acceleration[i], rtol=0, atol=1e-8 * (1 + np.abs(m.acceleration[i]).max()),
                                   err_msg=str(q[i]))
        M = hexatwist.mass_matrix(rig, q[i])
        np.testing.assert_allclose(M, M.T, atol=1e-9 * np.abs(M).max())
        v = m.velocity[i]
        assert hexatwist.kinetic_energy(rig, q[i], v) == pytest.approx(0.5 * v @ M @ v, rel=1e-12)
        # M x'' + bias = J_phi^T (torque - friction)
        J = hexatwist.motor_jacobian(rig, q[i])
        lhs = M @ m.acceleration[i] + hexatwist.bias(rig, q[i], v)
        np.testing.assert_allclose(lhs, J.T @ (r.torque[i] - r.friction[i]), atol=1e-8 * np.abs(lhs).max())
    parts = sum(r[k][r.ok] for k in hexatwist.TORQUE_TERMS)
    np.testing.assert_allclose(parts, r.torque[r.ok], rtol=0, atol=1e-9)
    np.testing.assert_array_equal(r.power[r.ok], r.torque[r.ok] * r.speed[r.ok])


def test_power_of_the_net_torque_is_the_rate_of_the_mechanical_energy(rig):
    # Along a smooth motion: d(kinetic + potential)/dt = sum((torque - friction) * speed).
    dt = 1e-4
    t = np.arange(-2, 3) * dt + 0.37
    w = np.array([1.3, 0.9, 1.7, 2.1, 1.1, 1.5])
    a = np.array([0.1, -0.08, 0.12, 0.1, -0.12, 0.15])
    q = a * np.sin(w * t[:, None])
    qd = a * w * np.cos(w * t[:, None])
    qdd = -a * w ** 2 * np.sin(w * t[:, None])
    r = hexatwist.inverse_dynamics(rig, q, qd, qdd)
    assert r.ok.all()
    m = hexatwist.platform_motion(q, qd, qdd)
    e = np.array([hexatwist.kinetic_energy(rig, q[k], m.velocity[k]) + hexatwist.potential_energy(rig, q[k])
                  for k in range(5)])
    de = (e[0] - 8 * e[1] + 8 * e[3] - e[4]) / (12 * dt)
    power = np.sum((r.torque[2] - r.friction[2]) * r.speed[2])
    assert de == pytest.approx(power, rel=1e-6, abs=1e-6)
    # The motor speed is the time derivative of the motor angle.
    np.testing.assert_allclose((r.angle[3] - r.angle[1]) / (2 * dt), r.speed[2], rtol=1e-6, atol=1e-8)


def test_batch_is_independent_of_threads_and_equals_one_pose(rig):
    q, qd, qdd = motions(3 * hexatwist.BLOCK + 5, seed=3)
    before = hexatwist.get_num_threads()
    try:
        hexatwist.set_num_threads(1)
        one = hexatwist.inverse_dynamics(rig, q, qd, qdd)
        hexatwist.set_num_threads(2)
        two = hexatwist.inverse_dynamics(rig, q, qd, qdd)
    finally:
        hexatwist.set_num_threads(0 if before == os.cpu_count() else before)
    for k in PARTS + ("status",):
        assert np.array_equal(one[k], two[k], equal_nan=True), k
    single = hexatwist.inverse_dynamics(None, q[7], qd[7], qdd[7])
    assert single.torque.shape == (6,) and single.status.shape == ()
    assert np.array_equal(single.torque, one.torque[7], equal_nan=True)


def test_rig_from_yaml_path_pickle_and_seed_agree(rig, tmp_path):
    q, qd, qdd = motions(500, seed=9)
    base = hexatwist.inverse_dynamics(rig, q, qd, qdd)
    path = tmp_path / "seed.yaml"
    path.write_text(hexatwist.seed_config_yaml())
    for other in (pickle.loads(pickle.dumps(rig)), hexatwist.Rig(path), hexatwist.Rig(str(path)),
                  hexatwist.seed_config_yaml(), None):
        r = hexatwist.inverse_dynamics(other, q, qd, qdd)
        assert np.array_equal(r.torque, base.torque, equal_nan=True)
    assert rig.control_period == hexatwist.control_period(rig) == 1e-3
    assert rig.servo["torque_limit"] == 28.0 and rig.load["inertia"].shape == (3, 3)
    assert np.array_equal(rig.model.base, hexatwist.default_model().base)
    text = hexatwist.seed_config_yaml()
    assert "mass: 1500" in text
    heavy = hexatwist.Rig(text.replace("mass: 1500", "mass: 3000", 1))
    assert heavy.load["mass"] == 3000
    home = np.zeros(6)
    g0 = hexatwist.inverse_dynamics(rig, home, home, home).gravity
    g1 = hexatwist.inverse_dynamics(heavy, home, home, home).gravity
    assert np.abs(g1).sum() > 1.5 * np.abs(g0).sum()  # the config reached the dynamics
    # A simulate on a Rig equals one on its text.
    qs = np.zeros((300, 6))
    qs[:, 2] = np.linspace(0, 0.01, 300)
    assert np.array_equal(hexatwist.simulate(rig, poses=qs).actual, hexatwist.simulate(rig.yaml, poses=qs).actual)


def one_line(excinfo):
    msg = str(excinfo.value)
    assert msg and "\n" not in msg, msg
    return msg


@pytest.mark.parametrize("call, error, text", [
    (lambda: hexatwist.inverse_dynamics(None, np.zeros((3, 6)), np.zeros((2, 6)), np.zeros((3, 6))),
     hexatwist.InputError, "pose_rates: expected the shape of poses"),
    (lambda: hexatwist.inverse_dynamics(None, np.zeros((3, 6)), np.zeros((3, 6)), [[0, 0, 0, 0, 0, np.inf]] * 3),
     hexatwist.InputError, "pose_accelerations: row 0 holds NaN or inf"),
    (lambda: hexatwist.inverse_dynamics(None, np.zeros((3, 6), np.float32), np.zeros((3, 6)), np.zeros((3, 6))),
     TypeError, "float64"),
    (lambda: hexatwist.forward_dynamics(None, np.zeros(6), np.zeros(5), np.zeros(6)), hexatwist.InputError,
     "velocity"),
    (lambda: hexatwist.kinetic_energy(None, [0, 0, np.nan, 0, 0, 0], np.zeros(6)), hexatwist.InputError, "pose"),
    (lambda: hexatwist.Rig("servo: {torque_limit: -1}\n"), hexatwist.ConfigError, "<yaml>:"),
    (lambda: hexatwist.size_motors(None), hexatwist.InputError, "trajectory"),
    (lambda: hexatwist.size_motors(None, poses=np.zeros((1, 6))), hexatwist.InputError, "at least 2 poses"),
    (lambda: hexatwist.size_motors(None, "t,x,y,z,roll,pitch,yaw\n0,0,0,0,0,0,0\n1,0,0,abc,0,0,0\n"),
     hexatwist.ConfigError, "abc"),
])
def test_bad_input_raises_one_line(call, error, text):
    with pytest.raises(error) as e:
        call()
    assert text in one_line(e)


@pytest.fixture(scope="module")
def simulator_csv():
    path = os.path.join(os.environ.get("HEXATWIST_SOURCE_DIR", ""), "examples", "motion_simulator.csv")
    if not os.path.exists(path):
        pytest.skip("HEXATWIST_SOURCE_DIR not set")
    return path


def test_size_motors_equals_the_library_bit_for_bit(rig, simulator_csv, tmp_path):
    s = hexatwist.size_motors(rig, simulator_csv)
    n = len(s.time)
    ref = reference("sizing", simulator_csv, tmp_path, None)
    per = ref[:n * 55].reshape(n, 55)
    assert np.array_equal(s.time, per[:, 0])
    for j, name in enumerate(("torque", "speed", "power") + hexatwist.TORQUE_TERMS):
        assert np.array_equal(s[name], per[:, 1 + 6 * j:7 + 6 * j]), name
    motors = ref[n * 55:n * 55 + 90].reshape(6, 15)
    for leg, m in enumerate(s.summary["motors"]):
        got = [m[k] for k in ("peak_torque", "rms_torque", "peak_speed", "peak_power", "energy_driven",
                              "energy_regenerated")] + [m["share"][t] for t in hexatwist.TORQUE_TERMS] + \
              [m["peak_usage"], m["speed_usage"], m["rms_usage"]]
        assert got == motors[leg].tolist(), leg
    check, leg, index, time, value, bound, status = ref[n * 55 + 90:]
    v = s.summary["first_violation"]
    assert status == 0 and s.summary["status"] == "ok"
    # The fast cue exceeds the seed motor (as `hexatwist dynamics` reports: leg 4 at 0.930 s); the
    # library's leg index (0-based) is Python's leg number minus one.
    assert s.summary.envelope == "exceeded" and check == 1 and v.check == "speed"
    assert (v.leg - 1, v.index, v.time, v.value, v.bound) == (leg, index, time, value, bound)
    assert v.leg == 4 and v.time == pytest.approx(0.93)


def test_size_motors_reaches_the_verdict_of_hexatwist_dynamics(rig, simulator_csv, tmp_path):
    # Side by side with the command line's summary.json: the same violation, the same leg number.
    out = tmp_path / "dynamics-out"
    run = subprocess.run([tool("HEXATWIST_CLI"), "dynamics", "--trajectory", simulator_csv, "--no-figures", "--out",
                          str(out)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 3, run.stderr  # the motor envelope exceeded
    cli = json.loads((out / "summary.json").read_text())
    s = hexatwist.size_motors(rig, simulator_csv).summary
    v, c = s.first_violation, cli["first_violation"]
    assert v is not None and (v.check, v.leg, v.time, v.value, v.bound) == \
        (c["check"], c["leg"], c["time"], c["value"], c["bound"])
    assert f"leg {v.leg} " in c["message"] and s.samples == cli["samples"]


def test_size_motors_from_poses_and_inverse_dynamics_agree(rig, simulator_csv):
    s = hexatwist.size_motors(rig, simulator_csv)
    again = hexatwist.size_motors(rig, poses=s.poses)
    assert np.array_equal(again.torque, s.torque) and again.summary == s.summary
    timed = hexatwist.size_motors(rig, times=s.time, poses=s.poses)
    assert np.array_equal(timed.torque, s.torque)
    # The same rates and accelerations by central differences here: inverse_dynamics gives the torques.
    q, dt = s.poses, rig.control_period
    qd = np.gradient(q, dt, axis=0, edge_order=1)
    qdd = np.zeros_like(q)
    qdd[1:-1] = (q[2:] - 2 * q[1:-1] + q[:-2]) / dt ** 2
    r = hexatwist.inverse_dynamics(rig, q, qd, qdd)
    assert r.ok.all()
    np.testing.assert_allclose(r.torque[1:-1], s.torque[1:-1], rtol=1e-9, atol=1e-9)
    f = s.figure
    for leg in range(6):
        assert np.array_equal(f["operating"][leg]["speed"], s.speed[:, leg])
        assert np.array_equal(f["operating"][leg]["torque"], s.torque[:, leg])
    assert np.abs(f["envelope"]["torque"]).max() == rig.servo["torque_limit"]
    assert f["max_speed"] == rig.servo["max_speed"] and f["continuous_torque"] == rig.servo["continuous_torque"]
    for leg, m in enumerate(s.summary["motors"]):
        assert m["peak_torque"] == np.abs(s.torque[:, leg]).max()
        assert m["rms_torque"] == pytest.approx(np.sqrt(np.mean(s.torque[:, leg] ** 2)), rel=1e-12)
        assert hexatwist.peak_torque_at(rig, m["peak_speed"]) <= rig.servo["torque_limit"]


def test_size_motors_reports_a_limit_as_status(rig):
    q = np.zeros((20, 6))
    q[10:, 2] = np.linspace(0.0, 3.0, 10)
    s = hexatwist.size_motors(rig, poses=q)
    assert s.summary["status"] == "stroke_above_max" and s.summary["motors"] is None
    assert s.summary["failed_index"] == len(s.time) >= 11
