# SPDX-License-Identifier: BSD-3-Clause
"""Where to measure from Python (plan_stations, theory §13) is the CLI's plan (issue 21): the same
stations, criterion and predicted accuracy as ``hexatwist stations --json`` to the last bit, the run
``stations_run`` makes of them the rows of the CLI's --out file, planned stations better determined
than random ones, and a value out of its range refused naming its keyword.
"""
import json
import os
import subprocess

import numpy as np
import pytest

import hexatwist

CLI = os.environ.get("HEXATWIST_CLI")


@pytest.fixture(scope="module")
def plan():
    return hexatwist.plan_stations(count=16, seed=3, candidates=600, accuracy_poses=300)


def test_the_plan_determines_the_model_better_than_random_stations(plan):
    assert plan.status == "ok", plan.reason
    assert plan.stations.shape == (16, 6)
    assert plan.planned.status == plan.random.status == "ok"
    assert plan.planned.criterion > plan.random.criterion
    assert plan.planned.accuracy.max < plan.random.accuracy.max
    assert len(plan.parameter_names) == plan.planned.covariance.shape[0] == plan.planned.sd.shape[0]
    # Every station within the range; the random ones are stations_run's of the same seed.
    assert np.all(np.abs(plan.stations[:, :3]) <= 0.25) and np.all(np.abs(plan.stations[:, 3:]) <= np.radians(15))
    np.testing.assert_array_equal(plan.random.stations, hexatwist.stations_run(count=16, seed=3).stations)


@pytest.mark.skipif(not CLI, reason="the command-line tool is not built")
def test_python_and_the_cli_plan_the_same_run_bit_for_bit(plan, tmp_path):
    r = subprocess.run([CLI, "stations", "--count", "16", "--seed", "3", "--candidates", "600", "--json",
                        "--out", "run.csv"], cwd=tmp_path, capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, r.stderr
    cli = json.loads(r.stdout)
    assert cli["candidates"] == plan.candidates and cli["exchanges"] == plan.exchanges
    assert cli["parameters"] == list(plan.parameter_names)
    np.testing.assert_array_equal(np.array(cli["planned"]["stations"]), plan.stations)
    for key in ("planned", "random"):
        assert cli[key]["criterion"] == plan[key].criterion
        np.testing.assert_array_equal(cli[key]["sd"], plan[key].sd)
        np.testing.assert_array_equal(np.array(cli[key]["stations"]), plan[key].stations)
    # The accuracy: the CLI predicts it over 1000 poses.
    full = hexatwist.plan_stations(count=16, seed=3, candidates=600)
    assert cli["planned"]["accuracy"]["max"] == full.planned.accuracy.max
    assert cli["random"]["accuracy"]["median"] == full.random.accuracy.median
    # The run written: stations_run of the planned stations, every 10th control sample (100 Hz).
    rows = np.loadtxt(tmp_path / "run.csv", delimiter=",", skiprows=1)
    run = hexatwist.stations_run(stations=plan.stations)
    every = round(0.01 / hexatwist.control_period())
    index = list(range(0, len(run.t), every))
    if index[-1] != len(run.t) - 1:
        index.append(len(run.t) - 1)
    np.testing.assert_array_equal(rows[:, 0], run.t[index])
    np.testing.assert_array_equal(rows[:, 1:], run.poses[index])


@pytest.mark.parametrize("keyword, value", [("count", 12), ("count", 10001), ("candidates", 10),
                                            ("translation", float("nan")), ("rotation", -0.1), ("noise", 0.0),
                                            ("points_per_station", 0), ("accuracy_poses", 0)])
def test_a_value_out_of_its_range_names_its_keyword(keyword, value):
    with pytest.raises(hexatwist.InputError, match=rf"\[{keyword}\]$"):
        hexatwist.plan_stations(**{"count": 16, "candidates": 600, keyword: value})
