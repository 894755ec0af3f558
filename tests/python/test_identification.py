# SPDX-License-Identifier: BSD-3-Clause
"""Identification from Python reaches the CLI's decisions on the same data, bit for bit (issues 21, 24):
a log made by ``hexatwist synth`` with joint-centre errors, identified by ``hexatwist identify --json``
and by the Python pipeline (read_point_log, stations_run, observations_at_rest, identify with its
defaults): the same status, the same estimate to the last bit, the same corrected configuration; the
basic model refused by both on the same data; per-leg targets of a multi-target log.
"""
import json
import os
import subprocess

import numpy as np
import pytest

import hexatwist

CLI = os.environ.get("HEXATWIST_CLI")
pytestmark = pytest.mark.skipif(not CLI, reason="the command-line tool is not built")


def run(*args, cwd, check=True):
    r = subprocess.run([CLI, *args], cwd=cwd, capture_output=True, text=True, timeout=240)
    if check:
        assert r.returncode == 0, r.stderr
    return r


@pytest.fixture(scope="module")
def log_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("identify")
    run("synth", "--stations", "30", "--station-seed", "4", "--lead-error-pct", "2", "--offsets-mm", "0.5",
        "--point-offset-mm", "1,-2,1.5", "--joint-errors-mm", "1", "--seed", "6", "--out", "s.csv", cwd=d)
    run("synth", "--stations", "30", "--station-seed", "4", "--joint-errors-mm", "1", "--seed", "6",
        "--targets-mm", "-600,1000,20;-600,-1000,-30", "--out", "t.csv", cwd=d)
    return d


def python_identification(log_path, **options):
    model = hexatwist.default_model()
    log = hexatwist.read_point_log(str(log_path))
    stations = hexatwist.stations_run(count=30, seed=4)
    obs = hexatwist.observations_at_rest(model, stations.t, stations.poses, log.stamps, log.points,
                                         targets=log.targets)
    return model, hexatwist.identify(model, obs.motor, obs.points, obs.targets, times=obs.time,
                                     approach=obs.approach, **options)


def test_python_and_the_cli_reach_the_same_estimate_bit_for_bit(log_dir):
    cli = json.loads(run("identify", "--points", "s.csv", "--stations", "30", "--station-seed", "4", "--json",
                         "--no-figures", cwd=log_dir).stdout)
    model, py = python_identification(log_dir / "s.csv")
    assert cli["status"] == "ok" and py.status == "ok", py.reason
    names = [p["name"] for p in cli["estimate"]["parameters"]]
    assert names == list(py.parameter_names)
    np.testing.assert_array_equal([p["estimate"] for p in cli["estimate"]["parameters"]], py.estimate)
    np.testing.assert_array_equal([p["sd"] for p in cli["estimate"]["parameters"]], py.sd)
    assert cli["sigma"] == py.sigma and cli["fit_test"]["z"] == py.fit_z
    assert cli["accuracy"]["median"] == py.accuracy["median"]
    # The worst stations, numbered from 1 in both.
    assert [(w["station"], w["points"], w["statistic"]) for w in cli["worst_stations"]] == \
        [(w.station, w.count, w.statistic) for w in py.worst] and len(py.worst) > 0
    # The corrected configuration: Python writes the CLI's file, byte for byte but for the header
    # comments and the name, which the CLI gives the log's file name.
    def body(text):
        return [line for line in text.splitlines() if not line.startswith(("#", "name:"))]
    written = (log_dir / "identified.yaml").read_text()
    assert body(written) == body(hexatwist.corrected_config(None, py.corrected_model))


def test_the_basic_model_on_joint_errors_is_refused_by_both(log_dir):
    cli = run("identify", "--points", "s.csv", "--stations", "30", "--station-seed", "4", "--model", "basic",
              "--json", "--out", "basic.yaml", cwd=log_dir, check=False)
    assert cli.returncode == 5 and not (log_dir / "basic.yaml").exists()
    result = json.loads(cli.stdout)
    _, py = python_identification(log_dir / "s.csv", calibration="basic")
    assert result["identification"] == py.status == "model_mismatch"
    assert result["fit_test"]["z"] == py.fit_z and py.fit_z > 5
    assert "geometry" in py.hint and py.corrected_model is None


def test_several_targets_each_get_their_point(log_dir):
    _, py = python_identification(log_dir / "t.csv")
    assert py.status == "ok", py.reason
    truth = json.loads((log_dir / "t.truth.json").read_text())["real"]["targets"]
    assert len(py.targets) == 3
    for t, (est, true) in enumerate(zip(py.targets, truth)):
        sd = py.sd[py.parameter_names.index("A x" if t == 0 else f"target {t + 1} x"):][:3]
        assert np.all(np.abs(est - true) < 4 * sd + 1e-9), (t, est - true, sd)


def test_bad_arguments_raise_one_line():
    model = hexatwist.default_model()
    motor = np.tile(model.length_home, (10, 1))
    with pytest.raises(hexatwist.InputError, match="calibration"):
        hexatwist.identify(model, motor, np.zeros((10, 3)), calibration="exact")
    with pytest.raises(hexatwist.InputError, match="targets"):
        hexatwist.identify(model, motor, np.zeros((10, 3)), targets=np.full(10, -1))
    with pytest.raises(hexatwist.InputError, match="NaN"):
        hexatwist.identify(model, motor, np.full((10, 3), np.nan))


def test_a_time_offset_outside_the_run_is_refused_by_both_naming_the_parameter(log_dir):
    # The library blames the time offset (ParameterError): the CLI names its option, Python its keyword,
    # on the same point of the same log.
    cli = run("identify", "--points", "s.csv", "--stations", "30", "--station-seed", "4", "--time-offset", "-1000",
              "--no-figures", cwd=log_dir, check=False)
    assert cli.returncode == 2, cli.stderr
    assert cli.stderr.rstrip().endswith("[--time-offset]") and len(cli.stderr.strip().splitlines()) == 1
    model = hexatwist.default_model()
    log = hexatwist.read_point_log(str(log_dir / "s.csv"))
    stations = hexatwist.stations_run(count=30, seed=4)
    with pytest.raises(hexatwist.InputError) as raised:
        hexatwist.observations_at_rest(model, stations.t, stations.poses, log.stamps, log.points, time_offset=-1000.0)
    message = str(raised.value)
    assert message.endswith(" [time_offset]") and "\n" not in message
    # The same point (line 2 of the log, which Python was given as arrays) at the same time as the CLI's.
    assert message.startswith("point log:2:1: ") and cli.stderr.startswith("hexatwist: error: s.csv:2:1: ")
    assert message[len("point log:2:1: "):-len(" [time_offset]")] in cli.stderr
    with pytest.raises(hexatwist.InputError, match=r"settle.*\[settle\]$"):
        hexatwist.observations_at_rest(model, stations.t, stations.poses, log.stamps, log.points, settle=-1.0)


def test_a_temperature_column_gives_the_same_expansions_in_python_and_the_cli(tmp_path):
    # The log's temperature column (synth --temperature-column): heat fits each leg's expansion per
    # kelvin, the CLI and Python alike bit for bit, and both corrected configurations keep them.
    run("synth", "--stations", "30", "--station-seed", "4", "--joint-errors-mm", "0.5", "--seed", "6",
        "--temperature-rise-k", "2", "--temperature-column", "--out", "w.csv", cwd=tmp_path)
    cli = json.loads(run("identify", "--points", "w.csv", "--stations", "30", "--station-seed", "4", "--json",
                         "--no-figures", "--effects", "heat", "--out", "c.yaml", cwd=tmp_path).stdout)
    model = hexatwist.default_model()
    log = hexatwist.read_point_log(str(tmp_path / "w.csv"))
    assert log.temperatures.shape == log.stamps.shape and log.temperatures[0] == 20.0 and log.temperatures[-1] > 21.9
    stations = hexatwist.stations_run(count=30, seed=4)
    obs = hexatwist.observations_at_rest(model, stations.t, stations.poses, log.stamps, log.points,
                                         temperatures=log.temperatures)
    py = hexatwist.identify(model, obs.motor, obs.points, effects="heat", times=obs.time, approach=obs.approach,
                            temperatures=obs.temperature)
    assert cli["status"] == "ok" and py.status == "ok", py.reason
    names = [p["name"] for p in cli["estimate"]["parameters"]]
    assert "expansion 1" in names and "lead expansion" in names and "drift 1" not in names
    assert list(py.parameter_names[:len(names)]) == names
    np.testing.assert_array_equal([p["estimate"] for p in cli["estimate"]["parameters"]], py.estimate[:len(names)])
    lead = names.index("lead expansion")
    assert abs(py.estimate[lead] - 11.5e-6) < 3.0 * py.sd[lead]
    text = (tmp_path / "c.yaml").read_text()
    assert "length_expansion:" in text and "lead_expansion:" in text and "reference_temperature: 20" in text
    # A temperature outside a machine's range is refused naming the file, line and column.
    bad = (tmp_path / "w.csv").read_text().splitlines()
    bad[5] = bad[5].rsplit(",", 1)[0] + ",400.000"
    (tmp_path / "bad.csv").write_text("\n".join(bad) + "\n")
    with pytest.raises(hexatwist.ConfigError, match=r"bad.csv:6:.*400 degC is not a machine's temperature"):
        hexatwist.read_point_log(str(tmp_path / "bad.csv"))


def test_the_legs_effects_are_chosen_and_fitted_alike_by_python_and_the_cli(tmp_path):
    # A machine whose legs warm 1 K, deflect at 200 N/um and have 50 um of play (theory §13b): the CLI's
    # --effects auto and Python's effects="auto", with the times and approaches observations_at_rest
    # gives, choose the same effects and reach the same estimate bit for bit; without them, refused.
    run("synth", "--stations", "30", "--station-seed", "4", "--joint-errors-mm", "0.5", "--seed", "6",
        "--temperature-rise-k", "1", "--stiffness-n-per-um", "200", "--play-um", "50", "--out", "w.csv",
        cwd=tmp_path)
    cli = json.loads(run("identify", "--points", "w.csv", "--stations", "30", "--station-seed", "4", "--json",
                         "--no-figures", "--effects", "auto", cwd=tmp_path).stdout)
    model = hexatwist.default_model()
    log = hexatwist.read_point_log(str(tmp_path / "w.csv"))
    stations = hexatwist.stations_run(count=30, seed=4)
    obs = hexatwist.observations_at_rest(model, stations.t, stations.poses, log.stamps, log.points)
    assert obs.time.shape == (len(obs.motor),) and obs.approach.shape == (len(obs.motor), 6)
    assert (obs.approach > 0).any(axis=0).all() and (obs.approach < 0).any(axis=0).all(), "both sides"
    py = hexatwist.identify(model, obs.motor, obs.points, effects="auto", times=obs.time, approach=obs.approach)
    assert cli["status"] == "ok" and py.status == "ok", py.reason
    assert cli["effects"] == py.effects and py.effects != "none", py.effects_choice
    assert cli["effects_choice"] == py.effects_choice
    np.testing.assert_array_equal([p["estimate"] for p in cli["estimate"]["parameters"]], py.estimate)
    plain = hexatwist.identify(model, obs.motor, obs.points)
    # Without the times, heat cannot be fitted: the refusal says what it needs.
    assert plain.status == "model_mismatch" and "heat: the legs' drift needs each observation's time" in plain.hint
    assert set(plain.diagnosis) == {"load", "heat"} and np.isnan(plain.diagnosis["heat"]), plain.diagnosis
    with pytest.raises(ValueError, match="warp"):
        hexatwist.identify(model, obs.motor, obs.points, effects="heat,warp")


def test_compare_is_the_clis_number_for_number(log_dir):
    """compare() and `hexatwist compare --json` on the nominal platform against the real one synth
    measured (s.real.yaml): the same differences and accuracy; the real platform against itself: none."""
    real_path = str(log_dir / "s.real.yaml")
    cli = json.loads(run("compare", os.path.join(os.path.dirname(__file__), "..", "..", "configs", "seed.yaml"),
                         real_path, "--stations", "20", "--station-seed", "3", "--json", cwd=log_dir).stdout)
    nominal, real = hexatwist.default_model(), hexatwist.load_model(real_path)
    py = hexatwist.compare(nominal, real, stations=20, station_seed=3)
    for leg_cli, leg_py in zip(cli["legs"], py.legs):
        for key in ("base", "platform"):
            assert list(getattr(leg_py, key)) == leg_cli[key], key
        for key in ("lead", "drive_lead", "length_offset", "home_command", "compliance", "play", "base_axis_angle"):
            assert getattr(leg_py, key) == leg_cli[key], key
    assert py.largest_joint == cli["largest_joint"] and py.largest_joint_leg == cli["largest_joint_leg"]
    for key in ("gauge_median", "gauge_max", "aligned_median", "aligned_max"):
        assert py.accuracy[key] == cli["accuracy"][key], key
    assert py.accuracy.gauge.shape == (20,) and py.accuracy.gauge_median > 1e-4
    assert abs(py.legs[0].lead - 0.02 * 0.010) < 1e-15
    same = hexatwist.compare(real, real, stations=10)
    assert same.largest_joint == 0.0 and same.accuracy.gauge_max < 1e-14
    with pytest.raises(hexatwist.InputError, match="stations"):
        hexatwist.compare(real, real, stations=3)
