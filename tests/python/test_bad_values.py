# SPDX-License-Identifier: BSD-3-Clause
"""Every batch function and option of the package given what a new user tries (#22): NaN, +-inf, 0, -1
and 1e300. Each call either returns a meaningful result (rows with a non-ok status where the input
is bad, never an ok row with NaN) or raises one hexatwist.Error with a one-line message naming the
argument, as the library, the C API and the CLI do."""
import numpy as np
import pytest

import hexatwist

BAD = [np.nan, np.inf, -np.inf, 0.0, -1.0, 1e300]


def one_line_error(call):
    with pytest.raises(hexatwist.Error) as e:
        call()
    msg = str(e.value)
    assert msg and "\n" not in msg, msg
    return msg


def check_rows(result, bad_rows, key):
    """The ok rows of a batch result are finite; rows given NaN or inf are never ok."""
    status = np.atleast_1d(result["status"])
    values = np.asarray(result[key]).reshape(len(status), -1)
    assert np.isfinite(values[status == 0]).all(), key
    for row in bad_rows:
        assert status[row] != 0, (key, row)


BATCH = [
    ("inverse_kinematics", lambda m, q: hexatwist.inverse_kinematics(m, q), "lengths"),
    ("twist", lambda m, q: hexatwist.twist(m, q), "twist"),
    ("commands", lambda m, q: hexatwist.commands(m, q), "commands"),
    ("inverse_dynamics", lambda m, q: hexatwist.inverse_dynamics(None, q, np.zeros_like(q), np.zeros_like(q)),
     "torque"),
]


@pytest.mark.parametrize("name,call,key", BATCH, ids=[b[0] for b in BATCH])
@pytest.mark.parametrize("value", BAD)
def test_a_bad_pose_value_is_a_status_or_one_error(model, name, call, key, value):
    for column in range(6):
        q = np.zeros((3, 6))
        q[1, column] = value
        try:
            r = call(model, q)
        except hexatwist.Error as e:
            assert "\n" not in str(e), str(e)
            # A finite number is never called NaN or inf.
            assert np.isnan(value) or np.isinf(value) or "NaN or inf" not in str(e), str(e)
            continue
        check_rows(r, [1] if not np.isfinite(value) else [], key)


@pytest.mark.parametrize("value", BAD)
def test_forward_refuses_lengths_and_options_outside_their_ranges(model, value):
    home = hexatwist.motor_command(model, np.zeros(6))
    lengths = np.tile(home, (2, 1))
    lengths[1, 2] = value
    if value > 0 and np.isfinite(value):
        try:
            r = hexatwist.forward(model, lengths)
            check_rows(r, [], "poses")
            assert r.status[1] != 0
        except hexatwist.Error as e:
            assert "lengths: row 1" in str(e) and "\n" not in str(e)
    else:
        msg = one_line_error(lambda: hexatwist.forward(model, lengths))
        assert "lengths: row 1" in msg
    for option in ("tolerance", "max_iterations"):
        v = value if option == "tolerance" else (int(value) if np.isfinite(value) and abs(value) < 1e9 else -5)
        if option == "tolerance" and 0 < v <= 1e-6:
            continue
        msg = one_line_error(lambda: hexatwist.forward(model, np.tile(home, (2, 1)), **{option: v}))
        assert option in msg
        msg = one_line_error(lambda: hexatwist.forward_kinematics_tracked(model, np.tile(home, (2, 1)), **{option: v}))
        assert option in msg


def test_a_loose_tolerance_is_refused_as_the_c_api_and_the_cli_refuse_it(model):
    home = hexatwist.motor_command(model, np.zeros(6))
    assert "tolerance" in one_line_error(lambda: hexatwist.forward(model, home + 0.3, tolerance=0.5))


def test_a_finite_but_huge_pose_is_too_large_not_nan(model):
    msg = one_line_error(lambda: hexatwist.commands(model, np.array([[1e300, 0, 0, 0, 0, 0]])))
    assert "too large" in msg and "NaN" not in msg


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf, 1e300])
def test_size_motors_refuses_a_start_time_or_period_that_is_no_time(value):
    q = np.zeros((20, 6))
    q[:, 2] = np.linspace(0, 0.01, 20)
    one_line_error(lambda: hexatwist.size_motors(None, poses=q, t0=value))
    if not (np.isfinite(value) and value > 0):
        one_line_error(lambda: hexatwist.size_motors(None, poses=q, dt=value))


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_the_envelope_refuses_a_speed_that_is_no_number(value):
    assert "speed" in one_line_error(lambda: hexatwist.peak_torque_at(None, value))


def test_a_study_stopped_by_a_limit_reports_no_errors_as_zeros():
    q = np.zeros((20, 6))
    q[10:, 2] = 2.0  # far beyond the stroke
    s = hexatwist.study(poses=q)
    assert s.summary["status"] == "stroke_above_max"
    assert s.summary["conventional"] is None and s.summary["compensated"] is None
    r = hexatwist.simulate(poses=q)
    assert r.summary["status"] == "stroke_above_max" and r.summary["error_max"] is None


def test_a_test_and_poses_together_are_refused():
    q = hexatwist.study_trajectory(test="Rz")[:50]
    for f in (hexatwist.simulate, hexatwist.study):
        assert "not both" in one_line_error(lambda: f(None, test="Rz", poses=q))
    assert "Lq" in one_line_error(lambda: hexatwist.study(None, test="Lq"))


def test_too_many_poses_are_refused_before_any_work():
    n = hexatwist.MAX_TRAJECTORY_SAMPLES + 1
    q = np.zeros((n, 6))
    assert "1,000,000" in one_line_error(lambda: hexatwist.simulate(None, poses=q))


@pytest.mark.parametrize("chunk", [0, -1, 2.5, True])
def test_map_batch_refuses_a_chunk_that_is_no_count(model, chunk):
    assert "chunk" in one_line_error(lambda: hexatwist.map_batch("commands", model, np.zeros((4, 6)), chunk=chunk))


def test_a_stream_whose_rate_limit_can_never_apply_is_refused(model):
    msg = one_line_error(lambda: hexatwist.Stream(model, period=1e300, max_velocity=1.0))
    assert "max_velocity" in msg and "never apply" in msg


def test_a_folder_or_an_endless_file_as_a_configuration_says_what_it_is(tmp_path):
    assert "is a directory" in one_line_error(lambda: hexatwist.load_model(tmp_path))
    assert "longer than" in one_line_error(lambda: hexatwist.load_model("/dev/zero"))
