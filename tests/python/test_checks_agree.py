# SPDX-License-Identifier: BSD-3-Clause
"""The command line and Python accept the same values (#30): each option that the library checks
(check_stations_spec, check_station_plan_spec, check_tolerance_sigmas, check_tracker_calibration,
check_identification_options) given values inside, at and beyond its range's ends. For every value
both front ends refuse it naming the option (exit 2, the option in the message) or the keyword
(InputError, the keyword in the message), or neither does: their units converted, they hand the
library the same number and the library decides."""
import math
import subprocess

import numpy as np
import pytest

import hexatwist
from conftest import tool

# The documented ranges (the library's headers), to show that the cases reach both sides of each.
RANGES = {
    "translation": (0.0, 10.0), "rotation": (0.0, math.pi / 2), "noise": (0.0, 0.01), "tracker_noise": (0.0, 0.01),
    "points_per_station": (1, 100000), "candidates": (20, 100000), "folds": (2, 100),
    "base_joint": (0.0, 0.1), "base_axis": (0.0, math.radians(10.0)), "lead": (0.0, 0.1), "offset": (0.0, 0.1),
}


def inside(keyword, value):
    low, high = RANGES[keyword]
    if keyword in ("noise", "tracker_noise"):
        return low < value < high
    if keyword == "folds" and value == 0:
        return True
    return low <= value <= high * (1 + 1e-12)


def cli_refuses(args, option, tmp_path):
    r = subprocess.run([tool("HEXATWIST_CLI"), *args], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    refused = r.returncode == 2 and option in r.stderr
    # Anything else is a run that went through the checks: exit 0, or a later failure not naming it.
    assert refused or option not in r.stderr, r.stderr
    return refused


def python_refuses(call, keyword):
    try:
        call()
    except hexatwist.InputError as e:
        if f"[{keyword}]" in str(e) or str(e).startswith(f"{keyword}:"):
            return True
        return False
    except hexatwist.Error:
        return False
    return False


STATIONS = ["stations", "--count", "20", "--candidates", "100", "--out", "run.csv"]
# (CLI option, the value typed, Python keyword, the value in SI units)
STATION_CASES = [
    ("--range", f"{t:g},5", "translation", t) for t in (0.0, 5.0, 10.0, 10.001, -0.1)
] + [
    ("--range", f"0.25,{r:g}", "rotation", math.radians(r)) for r in (0.0, 45.0, 90.0, 90.01, -1.0)
] + [
    ("--noise-um", f"{n:g}", "noise", n / 1e6) for n in (1e-3, 10.0, 9999.0, 1e4, 0.0, -1.0)
] + [
    ("--points-per-station", str(p), "points_per_station", p) for p in (1, 100000, 100001, 0)
] + [
    ("--candidates", str(c), "candidates", c) for c in (19, 20, 100000, 100001)
]


@pytest.mark.parametrize("option,typed,keyword,value", STATION_CASES)
def test_stations_options(option, typed, keyword, value, tmp_path):
    args = [a for a in STATIONS]
    if option == "--candidates":
        i = args.index("--candidates")
        del args[i:i + 2]
    kwargs = dict(count=20, candidates=100)
    kwargs[keyword] = value
    cli = cli_refuses([*args, option, typed], option, tmp_path)
    py = python_refuses(lambda: hexatwist.plan_stations(**kwargs), keyword)
    assert cli == py, (option, typed, cli, py)
    assert py == (not inside(keyword, value)), (option, typed, py)


TOLERANCE = ["tolerance", "--platforms", "2", "--out", "tol", "--no-figures", "--no-csv"]
SIGMA_CASES = [
    ("--sigma-joint-um", j, {"base_joint": j * 1e-6, "platform_joint": j * 1e-6}) for j in (0.0, 50.0, 1e5, 1.001e5, -1.0)
] + [
    ("--sigma-axis-deg", a, {"base_axis": math.radians(a), "platform_axis": math.radians(a)}) for a in (0.0, 10.0, 10.01, -0.1)
] + [
    ("--sigma-lead-ppm", p, {"lead": p * 1e-6}) for p in (0.0, 1e5, 1.001e5, -1.0)
] + [
    ("--sigma-offset-um", o, {"offset": o * 1e-6}) for o in (0.0, 1e5, 1.001e5, -1.0)
]


@pytest.mark.parametrize("option,typed,sigmas", SIGMA_CASES)
def test_tolerance_sigmas(option, typed, sigmas, tmp_path):
    cli = cli_refuses([*TOLERANCE, option, f"{typed:g}"], option, tmp_path)
    py = python_refuses(lambda: hexatwist.tolerance(platforms=2, sigmas=sigmas), next(iter(sigmas)))
    assert cli == py, (option, typed, cli, py)
    assert py == (not inside(next(iter(sigmas)), next(iter(sigmas.values())))), (option, typed, py)


TRACKER_CASES = [("--tracker-noise-um", f"{n:g}", "noise", n / 1e6) for n in (1.0, 9999.0, 1e4, 0.0)] + [
    ("--points-per-station", str(p), "points_per_station", p) for p in (1, 100000, 100001, 0)
]


@pytest.mark.parametrize("option,typed,key,value", TRACKER_CASES)
def test_tolerance_tracker(option, typed, key, value, tmp_path):
    # The values are checked before any platform is calibrated: one platform is enough.
    cli = cli_refuses([*TOLERANCE[:2], "1", *TOLERANCE[3:], "--calibration", "stations:20", option, typed], option,
                      tmp_path)
    keyword = {"noise": "tracker_noise"}.get(key, key)
    tracker = {key: value}
    if key == "points_per_station" and value == 1:
        tracker["noise"] = 10e-6
    py = python_refuses(lambda: hexatwist.tolerance(platforms=1, calibration="stations:20", tracker=tracker), keyword)
    assert cli == py, (option, typed, cli, py)
    assert py == (not inside(keyword, value)), (option, typed, py)


IDENTIFY_CASES = [("--tracker-noise-um", f"{n:g}", "tracker_noise", n / 1e6) for n in (1.0, 9999.0, 1e4, 0.0, -5.0)] + [
    ("--folds", str(f), "folds", f) for f in (0, 1, 2, 100, 101, -1)
]


@pytest.mark.parametrize("option,typed,keyword,value", IDENTIFY_CASES)
def test_identify_options(option, typed, keyword, value, model, tmp_path):
    # The options are checked before the log is read: a log that is not there ends an accepted run.
    cli = cli_refuses(["identify", "--stations", "40", "--points", "missing.csv", option, typed], option, tmp_path)
    motor = np.zeros((3, 6))
    points = np.zeros((3, 3))
    py = python_refuses(lambda: hexatwist.identify(model, motor, points, **{keyword: value}), keyword)
    assert cli == py, (option, typed, cli, py)
    assert py == (not inside(keyword, value)), (option, typed, py)


WORKSPACE_CASES = [("test_samples", "test_samples", v, v) for v in (1, 2, 1000001)] + [
    ("random", "random", v, v) for v in (0, 200, 1000000001)
] + [("linear", "linear", v, v) for v in (0.0, 10.0, 10.001)] + [
    ("angular", "angular", v, math.radians(v)) for v in (0.0, 180.0, 180.01)
]


@pytest.mark.parametrize("key,keyword,typed,value", WORKSPACE_CASES)
def test_required_workspace(key, keyword, typed, value, tmp_path):
    # The tests on with 2 poses each (random poses only where the case is about them): an accepted
    # workspace is small, and `design` on it quick.
    base = {"tests": keyword != "random", "test_samples": 2, "random": 0}
    base[keyword] = value
    typed_keys = {"tests": "on" if base["tests"] else "off", "test_samples": 2, "random": 0}
    typed_keys[key] = str(typed)  # every digit: {:g} would round 1000001 to 1e+06
    text = ",".join(f"{k}={v}" for k, v in typed_keys.items())
    cli = cli_refuses(["design", "--out", "d.yaml", "--workspace", text], f"({keyword})", tmp_path)
    py = python_refuses(lambda: hexatwist.required_workspace(**base), keyword)
    assert cli == py, (key, typed, cli, py)
    limits = {"test_samples": (2, 1000000), "random": (0, 1000000000), "linear": (0.0, 10.0), "angular": (0.0, math.pi)}
    low, high = limits[keyword]
    empty = keyword == "random" and value == 0  # no tests, no random poses
    assert py == (not low <= value <= high * (1 + 1e-12) or empty), (key, typed, py)


def test_the_packages_workspace_defaults_are_the_librarys():
    import inspect
    from hexatwist import _hexatwist as core
    library = core._required_workspace_defaults()
    signature = inspect.signature(hexatwist.required_workspace).parameters
    for key, value in library.items():
        assert signature[key].default == value, key


DESIGN_CASES = [("--clearance", c, "clearance", math.radians(c)) for c in (0.0, 79.9, 80.0, -1.0)] + [
    ("--max-volume-loss", p, "max_volume_loss", p / 100.0) for p in (0.0, 100.0, 100.1, -0.1)
]


@pytest.mark.parametrize("option,typed,keyword,value", DESIGN_CASES)
def test_design_options(option, typed, keyword, value, tmp_path):
    # A small required workspace (five random poses, a coarse volume) keeps an accepted design quick.
    cli = cli_refuses(["design", "--out", "d.yaml", "--workspace", "tests=off,random=5", "--cell", "0.1", option,
                       f"{typed:g}"], option, tmp_path)
    py = python_refuses(lambda: hexatwist.design_axes(None, tests=False, random=5, cell=0.1, **{keyword: value}),
                        keyword)
    assert cli == py, (option, typed, cli, py)
    low, high = (0.0, math.radians(80.0)) if keyword == "clearance" else (0.0, 1.0)
    assert py == (not (low <= value < high if keyword == "clearance" else low <= value <= high)), (option, typed, py)
