# SPDX-License-Identifier: BSD-3-Clause
"""Trajectories from Python (hexatwist.motion, trajectory.hpp): the paper's sweeps are the study's tests
bit for bit, moves through waypoints stay on their lines within their limits, CSV files read in SI, and
their resampling is what motor sizing sizes."""
import os

import numpy as np
import pytest

import hexatwist

RAD = np.pi / 180.0


@pytest.mark.parametrize("test, coordinate, amplitude, limits", [
    ("Lz", 2, 0.5, (0.2, 0.5, 2.5)),
    ("Rz", 5, 30.0 * RAD, (15.0 * RAD, 45.0 * RAD, 180.0 * RAD)),
])
def test_a_sweep_is_the_study_test_bit_for_bit(test, coordinate, amplitude, limits):
    rig = hexatwist.Rig()  # the seed's study: amplitudes, limits and a dwell of 0.5 s
    velocity, acceleration, jerk = limits
    sweep = hexatwist.sweep_trajectory(coordinate, amplitude, velocity=velocity, acceleration=acceleration, jerk=jerk,
                                       dwell=0.5, dt=rig.control_period)
    study = hexatwist.study_trajectory(rig, test)
    assert sweep.poses.tobytes() == study.tobytes()
    assert sweep.dt == rig.control_period and sweep.t[0] == 0.0 and len(sweep.t) == len(sweep.poses)
    np.testing.assert_allclose(np.diff(sweep.t), sweep.dt, rtol=1e-9)
    path = sweep.poses[:, coordinate]
    assert path.max() == pytest.approx(amplitude, abs=1e-12) and path.min() == pytest.approx(-amplitude, abs=1e-12)
    assert (np.abs(np.diff(path)) <= velocity * sweep.dt * (1 + 1e-9)).all()
    assert np.delete(sweep.poses, coordinate, axis=1).tobytes() == np.zeros((len(path), 5)).tobytes()


def test_waypoints_are_reached_at_rest_on_straight_lines_within_the_limits():
    w = np.array([[0, 0, 0, 0, 0, 0], [0.1, -0.05, 0.2, 0, 0, 0], [0.1, -0.05, 0.2, 0.1, 0.05, -0.2]], dtype=float)
    dt, v, a = 1e-3, 0.2, 0.5
    tr = hexatwist.waypoint_trajectory(w, velocity=v, acceleration=a, jerk=2.5, dwell=0.3, dt=dt)
    assert np.array_equal(tr.poses[0], w[0]) and np.array_equal(tr.poses[-1], w[-1])
    hit = [int(np.flatnonzero((tr.poses == p).all(axis=1))[0]) for p in w]
    assert hit == sorted(hit) and hit[0] == 0
    for (p0, p1), (k0, k1) in zip(zip(w[:-1], w[1:]), zip(hit[:-1], hit[1:])):
        seg = tr.poses[k0:k1 + 1] - p0
        d = (p1 - p0) / np.linalg.norm(p1 - p0)
        along = seg @ d
        np.testing.assert_allclose(seg, np.outer(along, d), atol=1e-12)  # on the line
        assert (np.diff(along) >= -1e-15).all()  # never back
        speed = np.diff(along) / dt
        assert speed.max() <= v * (1 + 1e-9) and np.abs(np.diff(speed) / dt).max() <= a * (1 + 1e-6)
    # At rest at each waypoint for the dwell: its pose held for 0.3 s.
    k = hit[1]
    assert (tr.poses[k:k + 300] == w[1]).all()


def test_a_csv_reads_in_si_and_names_the_line_and_column_of_a_bad_cell():
    csv = "t_s,x_mm,y_mm,z_mm,roll_deg,pitch_deg,yaw_deg\n# a comment\n0,0,0,0,0,0,0\n0.5,10,20,30,1,2,3\n"
    tp = hexatwist.read_trajectory(csv)
    np.testing.assert_array_equal(tp.t, [0.0, 0.5])
    np.testing.assert_allclose(tp.poses[1], [0.01, 0.02, 0.03, RAD, 2 * RAD, 3 * RAD], rtol=1e-15)
    assert tp.lines.tolist() == [3, 4]
    with pytest.raises(hexatwist.ConfigError, match=r"<yaml>:4:\d+: .*pitch"):
        hexatwist.read_trajectory(csv.replace(",2,3\n", ",abc,3\n"))


def test_resampling_is_what_motor_sizing_sizes(tmp_path):
    source = os.environ.get("HEXATWIST_SOURCE_DIR", "")
    cue = os.path.join(source, "examples", "motion_simulator.csv")
    if not os.path.exists(cue):
        pytest.skip("HEXATWIST_SOURCE_DIR not set")
    rig = hexatwist.Rig()
    tp = hexatwist.read_trajectory(cue)
    tr = hexatwist.resample(tp.t, tp.poses, rig.control_period)
    sized = hexatwist.size_motors(rig, cue)
    assert tr.poses.tobytes() == sized.poses.tobytes() and np.array_equal(tr.t, sized.time)
    again = hexatwist.size_motors(rig, tr)  # a Trajectory as it is
    assert again.torque.tobytes() == sized.torque.tobytes() and again.summary == sized.summary
    with pytest.raises(hexatwist.InputError, match="not both"):
        hexatwist.size_motors(rig, tr, dt=0.001)


def test_bad_arguments_raise_one_line():
    for call, text in [
        (lambda: hexatwist.sweep_trajectory(5, -0.1, velocity=1, acceleration=1, jerk=1, dwell=0, dt=1e-3),
         "amplitude"),
        (lambda: hexatwist.sweep_trajectory(7, 0.1, velocity=1, acceleration=1, jerk=1, dwell=0, dt=1e-3),
         "coordinate"),
        (lambda: hexatwist.sweep_trajectory(0, 0.1, velocity=1, acceleration=1, jerk=0, dwell=0, dt=1e-3), "jerk"),
        (lambda: hexatwist.waypoint_trajectory(np.zeros((1, 6)), velocity=1, acceleration=1, jerk=1, dwell=0, dt=1e-3),
         "waypoint"),
        (lambda: hexatwist.resample([0.0, 0.0], np.zeros((2, 6)), 1e-3), "resample: sample 1: time 0 s is not after"),
        (lambda: hexatwist.resample([0.0, 1.0], np.zeros((3, 6)), 1e-3), "as many"),
    ]:
        with pytest.raises(hexatwist.InputError) as e:
            call()
        assert text in str(e.value) and "\n" not in str(e.value), str(e.value)
