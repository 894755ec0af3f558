# SPDX-License-Identifier: BSD-3-Clause
"""Simulation, the study, the stream and identification through the bindings."""
import os

import numpy as np
import pytest

import hexatwist


def test_simulate_returns_time_series_and_summary():
    dt = hexatwist.control_period()
    t = np.arange(1500) * dt
    q = np.zeros((1500, 6))
    q[:, 5] = 0.02 * np.sin(np.pi * t / t[-1]) ** 2
    r = hexatwist.simulate(poses=q, strategy="compensated")
    assert r.summary["status"] == "ok", r.summary
    assert r.summary["ticks"] == 1500
    assert r.time.shape == (1500,) and r.actual.shape == (1500, 6) and r.torque.shape == (1500, 6)
    np.testing.assert_allclose(r.time, t, atol=1e-12)
    assert r.summary["error_max"] == pytest.approx(np.max(r.error))
    conv = hexatwist.simulate(poses=q, strategy="conventional")
    # Uncompensated twist: the conventional run misses the commanded point by more.
    assert conv.summary["error_max"] > r.summary["error_max"]


def test_simulate_reports_a_limit_as_status():
    q = np.zeros((10, 6))
    q[5:, 2] = 2.0
    r = hexatwist.simulate(poses=q)
    assert r.summary["status"] != "ok" and r.summary["index"] == 5


def test_study_summary_matches_its_series():
    q = hexatwist.study_trajectory(test="Rz")[:1500]
    s = hexatwist.study(poses=q)
    assert s.summary["status"] == "ok"
    for name in ("conventional", "compensated"):
        assert s.summary[name]["total"]["max"] == pytest.approx(np.max(s[name].error))
    assert s.summary["compensated"]["twist_only"]["max"] < s.summary["conventional"]["twist_only"]["max"]


def test_stream_answers_one_pose_at_a_time(model):
    st = hexatwist.Stream(model)
    st.start(np.zeros(6))
    a = st.pose([0, 0, 0.01, 0, 0, 0])
    assert a["status"] == "ok" and a["action"] == "new"
    np.testing.assert_array_equal(a["command"], hexatwist.motor_command(model, [0, 0, 0.01, 0, 0, 0]))
    b = st.pose([0, 0, 3.0, 0, 0, 0])
    assert b["status"] == "stroke_above_max" and b["action"] == "held"
    np.testing.assert_array_equal(b["command"], a["command"])


def test_identify_on_the_shipped_rz_log_reports_what_it_cannot_determine(model):
    log_path = os.path.join(os.environ.get("HEXATWIST_SOURCE_DIR", ""), "examples", "tracker_Rz.csv")
    if not os.path.exists(log_path):
        pytest.skip("HEXATWIST_SOURCE_DIR not set")
    log = hexatwist.read_point_log(log_path)
    assert log.points.shape == (2398, 3)
    run = hexatwist.measured_test(test="Rz")
    obs = hexatwist.observations_at_rest(model, run.t, run.poses, log.stamps, log.points)
    assert obs.motor.shape[0] == obs.points.shape[0] > 16
    r = hexatwist.identify(model, obs.motor, obs.points, calibration="basic")
    # A rotation about z cannot separate A's height from the tracker's: a status, not an exception.
    assert r.status == "not_identifiable" and "A z" in r.reason and "\n" not in r.reason


def test_point_log_errors_are_one_line():
    with pytest.raises(hexatwist.ConfigError) as e:
        hexatwist.read_point_log("t_s,x_mm,y_mm\n0,1,2\n")
    assert "\n" not in str(e.value)


def test_a_length_unit_is_honoured_or_refused_never_ignored():
    """Issue 29: a negative unit was ignored where the columns carry their units."""
    text = "t_s,x_mm,y_mm,z_mm\n0,1,2,3\n0.1,1,2,3\n0.2,1,2,4\n"
    assert hexatwist.read_point_log(text, length_unit=1e-3)["points"][2][2] == pytest.approx(4e-3)
    for unit in (-1e-3, float("nan"), float("inf")):
        with pytest.raises((hexatwist.ConfigError, ValueError)) as e:
            hexatwist.read_point_log(text, length_unit=unit)
        assert "length unit" in str(e.value)


def test_study_metrics_are_the_clis_side_by_side(tmp_path):
    """Python's study() and `hexatwist study` report the same run with the same library function
    (run_metrics): the errors, the largest torque, the saturated ticks, the following and orientation
    errors, number for number, on a motor weak enough to saturate."""
    import json
    import subprocess

    from conftest import tool

    config = tmp_path / "weak.yaml"
    config.write_text(hexatwist.seed_config_yaml().replace("  torque_limit: 28 ", "  torque_limit: 6.5 ")
                      .replace("  peak_torque_at_max_speed: 16 ", "  peak_torque_at_max_speed: 4 ")
                      .replace("  continuous_torque: 9.5 ", "  continuous_torque: 5 ")
                      .replace("  angular_amplitude_deg: 30 ", "  angular_amplitude_deg: 5 "))
    out = tmp_path / "out"
    run = subprocess.run([tool("HEXATWIST_CLI"), "study", "--config", str(config), "--tests", "Rz", "--no-figures",
                          "--no-csv", "--out", str(out)], capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    cli = json.loads((out / "summary.json").read_text())["tests"][0]
    py = hexatwist.study(str(config), test="Rz").summary
    assert py["status"] == "ok"
    saturated = 0
    for strategy in ("conventional", "compensated"):
        c, p = cli[strategy], py[strategy]
        for key in ("max_torque", "saturated_ticks", "max_following_error", "max_orientation_error"):
            assert c[key] == p[key], (strategy, key, c[key], p[key])
        for error in ("total", "twist_only", "tracking_only"):
            assert c[f"max_error_{error}"] == p[error]["max"] and c[f"rms_error_{error}"] == p[error]["rms"]
        saturated += p["saturated_ticks"]
        assert 0 < p["max_torque"] <= 6.5 and p["max_following_error"] > 0 and p["max_orientation_error"] > 0
    assert saturated > 0, "the weak motor saturates"


def test_the_leg_effects_costs_are_the_clis_and_their_compensation_removes_them(tmp_path):
    """A configuration with every leg effect: study()'s summary.leg_effects and `hexatwist study
    --temperature-rise-k` report the same costs, number for number; each effect moves point A by
    micrometres, compensated by less than a nanometre; a warm-up is refused where it means nothing."""
    import json
    import subprocess

    from conftest import tool

    config = tmp_path / "effects.yaml"
    config.write_text(hexatwist.seed_config_yaml().replace("  angular_amplitude_deg: 30 ", "  angular_amplitude_deg: 5 ")
                      + "\nleg_effects:\n  stiffness: 2.0e8\n  play: 50.0e-6\n  length_expansion: 11.5e-6\n"
                        "  lead_expansion: 11.0e-6\n")
    out = tmp_path / "out"
    run = subprocess.run([tool("HEXATWIST_CLI"), "study", "--config", str(config), "--tests", "Rz", "--no-figures",
                          "--no-csv", "--temperature-rise-k", "2", "--out", str(out)], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    assert "legs' effects, perfect servos" in run.stdout, run.stdout
    cli = json.loads((out / "summary.json").read_text())["tests"][0]["leg_effects"]
    py = hexatwist.study(str(config), test="Rz", temperature_rise=2.0).summary
    assert py.status == "ok"
    assert [e.effect for e in py.leg_effects] == ["load", "play", "heat", "all"]
    for c, p in zip(cli, py.leg_effects):
        assert c["effect"] == p.effect
        for column in ("conventional", "twist_compensated", "compensated", "static_load_compensated"):
            assert c[column]["max"] == p[column].max and c[column]["rms"] == p[column].rms, (p.effect, column)
        assert p.twist_compensated.max > 0.5e-6 and p.compensated.max < 2e-11, p
    with pytest.raises(hexatwist.InputError, match="temperature_rise"):
        hexatwist.study(str(config), test="Rz", temperature_rise=60.0)
    with pytest.raises(hexatwist.InputError, match="do not expand"):
        hexatwist.study(None, test="Rz", temperature_rise=[1, 1, 1, 1, 1, 2])
