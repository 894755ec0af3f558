# SPDX-License-Identifier: BSD-3-Clause
"""hexatwistkins in a real, headless LinuxCNC (and genhexkins beside it for comparison).

Run by ctest (integrations/linuxcnc/tests/CMakeLists.txt) with
  HEXATWIST_CLI      the built hexatwist command-line tool
  HEXATWISTKINS_SO   the built module (copied to LinuxCNC's modules folder: needs root)
  HEXATWIST_LINUXCNC_OUT  a folder for the comparison table and the kept LinuxCNC runs
"""
import json
import math
import os
import random
import re
import subprocess

import pytest

import linuxcnc_harness as harness

HERE = os.path.dirname(os.path.abspath(__file__))
CLI = os.environ.get("HEXATWIST_CLI", "hexatwist")
OUT = os.environ.get("HEXATWIST_LINUXCNC_OUT", "/tmp/hexatwist-linuxcnc-out")
WIDE = os.path.join(HERE, "seed-wide.yaml")
# Joint positions against `hexatwist ik`, and LinuxCNC's pose from the module's FK against the
# commanded pose (the bounds; the measured agreement is about 1e-12 mm).
JOINT_TOL_MM = 1e-6
POSE_TOL = 1e-6  # [mm and deg]
PINS = (["hexatwistkins.leg.%d.%s" % (i, p) for i in range(1, 7) for p in ("twist", "length-error", "length")] +
        ["hexatwistkins." + p for p in ("ik-status", "ik-refused", "limit-nearest", "limit-leg", "limit-margin",
                                        "condition", "fk-status", "fk-iterations", "fk-residual", "fk-fail",
                                        "fk-failures", "fk-recoveries")])


def cli(*args, check=True):
    r = subprocess.run([CLI, *args], capture_output=True, text=True, timeout=60)
    if check and r.returncode != 0:
        raise AssertionError("hexatwist %s: exit %d: %s" % (" ".join(args), r.returncode, r.stderr))
    return r


def temperature_args(temperatures):
    return ["--temperature-c", ",".join(repr(float(t)) for t in temperatures)] if temperatures else []


def ik(world, config=None, temperatures=None):
    """`hexatwist ik --json` for a LinuxCNC world pose [mm, deg] (Z absolute), the legs at
    `temperatures` [degC] (default: the reference)."""
    home_height = model_json(config)["home_height"]
    x, y, z, a, b, c = world
    pose = "%r,%r,%r,%r,%r,%r" % (x / 1000.0, y / 1000.0, z / 1000.0 - home_height, a, b, c)
    args = ["ik", "--json", "--pose=" + pose] + (["--config", config] if config else []) + temperature_args(temperatures)
    r = cli(*args, check=False)
    assert r.returncode in (0, 3), r.stderr
    return json.loads(r.stdout)


def fk(joints, config=None, temperatures=None):
    """`hexatwist fk --motor --json` of LinuxCNC joints [mm] as a LinuxCNC world pose [mm, deg]."""
    home_height = model_json(config)["home_height"]
    lengths = ",".join(repr(j / 1000.0) for j in joints)
    rep = json.loads(cli("fk", "--motor", "--json", "--lengths=" + lengths, *(["--config", config] if config else []),
                         *temperature_args(temperatures)).stdout)
    x, y, z, a, b, c = rep["pose"]
    return [1000 * x, 1000 * y, 1000 * (z + home_height), math.degrees(a), math.degrees(b), math.degrees(c)]


_models = {}


def model_json(config=None):
    if config not in _models:
        _models[config] = json.loads(cli("config", "--json", *(["--config", config] if config else [])).stdout)
    return _models[config]


def ini_for(config=None, *extra):
    args = ["linuxcnc"] + (["--config", config] if config else []) + list(extra)
    return harness.faster(cli(*args).stdout)


def axis_limits(ini):
    """{axis letter: (min, max)} from the INI's [AXIS_*] sections."""
    limits, axis = {}, None
    for line in ini.splitlines():
        if line.startswith("[AXIS_"):
            axis = line[6]
        elif line.startswith("["):
            axis = None
        elif axis and line.startswith(("MIN_LIMIT", "MAX_LIMIT")):
            lo, hi = limits.get(axis, (None, None))
            v = float(line.split("=")[1])
            limits[axis] = (v, hi) if line.startswith("MIN") else (lo, v)
    return limits


def g0(world):
    return "G0 " + " ".join("%s%.9f" % (k, v) for k, v in zip("XYZABC", world))


def assert_close(a, b, tol, what):
    worst = max(abs(x - y) for x, y in zip(a, b))
    assert worst <= tol, "%s: %r vs %r (worst difference %.3g)" % (what, a, b, worst)
    return worst


@pytest.fixture(scope="session", autouse=True)
def module_installed():
    so = os.environ.get("HEXATWISTKINS_SO")
    if not so:
        pytest.fail("HEXATWISTKINS_SO is not set: run these tests through ctest")
    try:
        harness.install_module(so)
    except PermissionError as e:
        pytest.fail("copying the module where LinuxCNC loads it needs root (%s): run the tests as root, or install "
                    "this build first: sudo cmake --install build --component linuxcnc" % e)
    os.makedirs(OUT, exist_ok=True)


def check_pose_steps(run, config=None, strategy="compensated"):
    """Every step that moved: joints = ik's command, FK pose = commanded pose; returns the worst."""
    worst_joint = worst_pose = 0.0
    for r in run.results:
        if not r["done"] or r["errors"]:
            continue
        rep = ik(r["position"], config)
        assert rep["status"] == "ok", (r["step"], rep["status"])
        command = [1000.0 * leg["command_" + strategy] for leg in rep["legs"]]
        worst_joint = max(worst_joint, assert_close(r["joint_actual_position"], command, JOINT_TOL_MM,
                                                    "joints after %s" % r["step"]))
        # With compensated commands the platform stands where commanded. With conventional ones it
        # does not: the module's FK reports where the twist put it, as hexatwist fk does.
        where = r["position"] if strategy == "compensated" else fk(r["joint_actual_position"], config)
        worst_pose = max(worst_pose, assert_close(r["actual_position"], where, POSE_TOL, "FK pose after %s" % r["step"]))
        # The pins a user watches say the same as `hexatwist ik`.
        pins = r["pins"]
        for i, leg in enumerate(rep["legs"], 1):
            assert abs(pins["hexatwistkins.leg.%d.twist" % i] - math.degrees(leg["twist"])) < 1e-9
            assert abs(pins["hexatwistkins.leg.%d.length-error" % i] - 1000 * leg["length_error"]) < 1e-9
        assert pins["hexatwistkins.fk-status"] == 0 and not pins["hexatwistkins.fk-fail"]
        assert 0 <= pins["hexatwistkins.limit-margin"] <= 1
    return worst_joint, worst_pose


def distance_to_path(p, path):
    """Distance of world pose p from the polyline `path` of world poses (mm and deg alike)."""
    best = math.inf
    for a, b in zip(path, path[1:]):
        d = [y - x for x, y in zip(a, b)]
        dd = sum(v * v for v in d)
        t = 0.0 if dd == 0 else max(0.0, min(1.0, sum((pi - ai) * di for pi, ai, di in zip(p, a, d)) / dd))
        best = min(best, math.sqrt(sum((pi - ai - t * di) ** 2 for pi, ai, di in zip(p, a, d))))
    return best


def random_inside(rng, limits, fraction, config=None, count=12):
    """Seeded random world poses with every coordinate within `fraction` of its axis range and
    inside every limit (checked by `hexatwist ik`)."""
    home_z = 1000 * model_json(config)["home_height"]
    poses = []
    while len(poses) < count:
        world = []
        for k in "XYZABC":
            lo, hi = limits[k]
            centre = home_z if k == "Z" else 0.0
            world.append(centre + fraction * rng.uniform(lo - centre, hi - centre))
        world = [round(v, 6) for v in world]
        if ik(world, config)["status"] == "ok":
            poses.append(world)
    return poses


def test_seed_platform_on_hexatwistkins_follows_hexatwist_ik():
    """Homes, sweeps yaw to both limits, moves to random combined poses by MDI, runs a G-code
    program; every joint is hexatwist's compensated command, every FK pose the commanded one, and
    poses past a limit are refused with the machine left where it was."""
    ini = ini_for()
    limits = axis_limits(ini)
    home_z = 1000 * model_json()["home_height"]
    rng = random.Random(11)
    c_lo, c_hi = limits["C"]
    steps = [{"home": True}]
    for c in list(range(5, int(c_hi) + 1, 5)) + [c_hi - 1e-3] + list(range(-5, int(c_lo) - 1, -5)) + [c_lo + 1e-3, 0]:
        steps.append({"mdi": g0([0, 0, home_z, 0, 0, c])})
    refused = [[0, 0, home_z, 0, 0, c_hi + 0.5],  # past the yaw limit (and the axis limit)
               [0.95 * limits["X"][1], 0.95 * limits["Y"][1], home_z, 0, 0, 0]]  # each axis inside, the pair not
    for world in refused:
        steps.append({"mdi": g0(world), "expect_refused": True})
    for world in random_inside(rng, limits, 0.6):
        steps.append({"mdi": g0(world)})
    program = os.path.join(OUT, "seed_moves.ngc")
    path = [[0, 0, home_z, 0, 0, 0]] + random_inside(rng, limits, 0.5, count=5) + [[0, 0, home_z, 0, 0, 0]]
    lines = ["G21 G90 G61", "G0 X0 Y0 Z%.3f A0 B0 C0" % home_z]
    lines += ["G1 F60000 " + " ".join("%s%.6f" % (k, v) for k, v in zip("XYZABC", world)) for world in path[1:]]
    lines.append("M2")
    with open(program, "w") as f:
        f.write("\n".join(lines) + "\n")
    steps.append({"program": program, "pauses": 12})

    run = harness.run(ini, {"steps": steps, "pins": PINS}, timeout=180, keep_dir=os.path.join(OUT, "seed-run"))
    assert run.results is not None, "LinuxCNC did not run the plan (%s):\n%s" % (run.returncode, run.log[-3000:])
    assert len(run.results) == len(steps), "stopped after %s:\n%s" % (run.results[-1], run.log[-3000:])
    before = None
    for r in run.results:
        if r["step"].get("expect_refused"):
            assert any("kinematicsInverse" in e or "exceed" in e for e in r["errors"]), r
            assert_close(r["position"], before["position"], 1e-9, "refused move left the machine where it was")
        else:
            assert r["done"] and not r["errors"], r
        before = r
    worst_joint, worst_pose = check_pose_steps(run)
    # The yaw sweep reached within 1e-3 deg of the module's limit on both sides.
    yaws = [r["position"][5] for r in run.results if r["done"] and not r["errors"]]
    assert max(yaws) > c_hi - 2e-3 and min(yaws) < c_lo + 2e-3
    # The program, held on its way: where it stood, the joints are hexatwist's command of the
    # commanded pose, the FK pose is that pose, and the pose is on the programmed path (whose
    # accuracy is LinuxCNC's: a micrometre).
    samples = run.results[-1]["samples"]
    assert len(samples) >= 10
    path = [run.results[-2]["position"]] + path  # the program starts where the last MDI move ended
    for s in samples:
        s["done"], s["errors"], s["step"] = True, [], "held at %r" % s["position"]
    check_pose_steps(harness.LinuxcncRun(samples, "", 0))
    worst_path = max(distance_to_path(s["position"], path) for s in samples)
    assert worst_path < 0.01, worst_path
    assert len({tuple(s["position"]) for s in samples}) == len(samples)
    refused_count = run.results[-1]["pins"]["hexatwistkins.ik-refused"]
    assert refused_count >= 1
    print("worst joint difference %.3g mm, worst FK pose difference %.3g; %d samples during the program, "
          "farthest %.3g from the path" % (worst_joint, worst_pose, len(samples), worst_path))


def test_conventional_strategy_sends_the_uncompensated_command():
    ini = ini_for(None, "--strategy", "conventional")
    home_z = 1000 * model_json()["home_height"]
    steps = [{"home": True}, {"mdi": g0([50, -30, home_z + 100, 4, -3, 25])}, {"mdi": g0([0, 0, home_z, 0, 0, -30])}]
    run = harness.run(ini, {"steps": steps, "pins": PINS}, timeout=120)
    assert run.results and len(run.results) == len(steps), run.log[-3000:]
    assert all(r["done"] and not r["errors"] for r in run.results)
    check_pose_steps(run, strategy="conventional")
    # Without compensation the platform misses the commanded pose by the twist's effect (about a
    # millimetre here), and LinuxCNC shows it: its actual position is not the commanded one.
    r = run.results[1]
    assert max(abs(a - b) for a, b in zip(r["actual_position"][:3], r["position"][:3])) > 0.1


def test_a_bad_configuration_stops_the_load_with_one_line():
    ini = ini_for().replace("KINEMATICS = hexatwistkins", "KINEMATICS = hexatwistkins config=/nonexistent/x.yaml")
    run = harness.run(ini, {"steps": [{"home": True}], "pins": []}, timeout=60)
    assert run.results is None and run.returncode != 0
    assert "hexatwistkins: /nonexistent/x.yaml: cannot read the configuration file" in run.log, run.log[-2000:]


def genhexkins_hal(config, lead_mm):
    """HAL commands that give genhexkins the platform of `config` and a screw lead [mm]."""
    m = model_json(config)
    lines = []
    for i, leg in enumerate(m["legs"]):
        for name, key in (("base", "base"), ("platform", "platform"), ("base-n", "base_axis"),
                          ("platform-n", "platform_axis")):
            scale = 1000.0 if name in ("base", "platform") else 1.0
            for axis, v in zip("xyz", leg[key]):
                lines.append("setp genhexkins.%s.%d.%s %.12g" % (name, i, axis, scale * v))
    lines.append("setp genhexkins.screw-lead %.12g" % lead_mm)
    return "\n".join(lines) + "\n"


def yaw_sweep(kins, config, yaws, lead_mm=None):
    """Runs LinuxCNC with `kins` on `config` through pure yaw moves; the steps after homing and
    a move to home."""
    ini = ini_for(config)
    home_z = 1000 * model_json(config)["home_height"]
    extra = None
    if kins == "genhexkins":
        ini = re.sub(r"(?m)^KINEMATICS = .*$", "KINEMATICS = genhexkins", ini)
        extra = genhexkins_hal(config, lead_mm)
    steps = [{"home": True}, {"mdi": g0([0, 0, home_z, 0, 0, 0])}] + [{"mdi": g0([0, 0, home_z, 0, 0, c])} for c in yaws]
    pins = PINS if kins == "hexatwistkins" else ["genhexkins.fwd-kins-fail", "genhexkins.last-iterations"]
    run = harness.run(ini, {"steps": steps, "pins": pins}, timeout=180, extra_hal=extra)
    assert run.results and len(run.results) == len(steps), "%s: %s\n%s" % (kins, run.returncode, run.log[-3000:])
    return run.results[1:]


def test_genhexkins_side_by_side_with_hexatwistkins():
    """The same platform, lead and yaw sweep in genhexkins (both signs of its screw-lead) and in
    hexatwistkins: the change of each joint from home against hexatwist's compensated command.
    Writes the table of the README (genhexkins_comparison.md in the output folder)."""
    yaws = list(range(5, 61, 5))
    lead_mm = 1000 * model_json(WIDE)["legs"][0]["lead"]
    runs = {"hexatwistkins": yaw_sweep("hexatwistkins", WIDE, yaws),
            "genhexkins +lead": yaw_sweep("genhexkins", WIDE, yaws, lead_mm),
            "genhexkins -lead": yaw_sweep("genhexkins", WIDE, yaws, -lead_mm)}
    truth_home = [1000 * leg["command_compensated"] for leg in ik(runs["hexatwistkins"][0]["position"], WIDE)["legs"]]
    rows = []
    worst = {name: [] for name in runs}
    for k, yaw in enumerate(yaws, 1):
        rep = ik(runs["hexatwistkins"][k]["position"], WIDE)
        assert rep["status"] == "ok", (yaw, rep["status"])
        truth = [1000 * leg["command_compensated"] - h for leg, h in zip(rep["legs"], truth_home)]
        twist = max(abs(math.degrees(leg["twist_absolute"])) for leg in rep["legs"])
        row = [yaw, twist]
        for name, results in runs.items():
            r, home = results[k], results[0]
            assert r["done"] and not r["errors"], (name, yaw, r["errors"])
            moved = [a - b for a, b in zip(r["joint_actual_position"], home["joint_actual_position"])]
            err = max(abs(a - b) for a, b in zip(moved, truth))
            worst[name].append(err)
            # Where the platform really goes: a machine homed at home, whose motors then move by
            # `moved`, stands at hexatwist's twist-aware FK of those motor-side lengths.
            real = fk([h + m for h, m in zip(truth_home, moved)], WIDE)
            position = math.dist(real[:3], r["position"][:3])
            rotation = max(abs(a - b) for a, b in zip(real[3:], r["position"][3:]))
            fk_failed = bool(r["pins"].get("genhexkins.fwd-kins-fail")) or bool(r["pins"].get("hexatwistkins.fk-fail"))
            row.append("%.3g | %.3g mm, %.4f deg%s" % (err, position, rotation, " (FK failed)" if fk_failed else ""))
        rows.append(row)
    header = ("| yaw [deg] | largest absolute twist [deg] | hexatwistkins: joint error [mm] | platform error |"
              " genhexkins, screw-lead +10 mm: joint error [mm] | platform error |"
              " genhexkins, screw-lead -10 mm: joint error [mm] | platform error |\n|" + "---|" * 8 + "\n")
    table = header + "".join("| %d | %.1f | %s | %s | %s |\n" % tuple(row) for row in rows)
    with open(os.path.join(OUT, "genhexkins_comparison.md"), "w") as f:
        f.write(table)
    print("\n" + table)
    # hexatwistkins commands hexatwist's compensated lengths, and its FK returns the commanded pose.
    assert max(worst["hexatwistkins"]) < JOINT_TOL_MM
    for r in runs["hexatwistkins"][1:]:
        assert_close(r["actual_position"], r["position"], POSE_TOL, "hexatwistkins FK at yaw %g" % r["position"][5])
    # genhexkins: neither sign of its screw-lead matches every leg once the twist grows.
    big = [i for i, yaw in enumerate(yaws) if yaw >= 20]
    assert min(worst["genhexkins +lead"][i] for i in big) > 0.1
    assert min(worst["genhexkins -lead"][i] for i in big) > 0.1


def test_sample_configuration_runs_headless():
    """sim/run.sh, as the README tells a new user to run it: homes and makes its moves."""
    r = subprocess.run(["bash", os.path.join(os.path.dirname(HERE), "sim", "run.sh")], capture_output=True, text=True,
                       timeout=120)
    try:
        assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
        assert r.stdout.count("done=True") == 4, r.stdout[-3000:]
        assert "twist [deg]" in r.stdout
    finally:
        harness.clean_stale()


def ini_values(ini, key):
    """Every `key = value` of the INI, in order, as text (the exact digits LinuxCNC reads)."""
    return [line.split("=", 1)[1].strip() for line in ini.splitlines() if line.split("=", 1)[0].strip() == key]


def test_a_calibrated_configuration_keeps_the_machines_home_and_runs_unchanged():
    """The calibration contract (README "Identification"): a platform identified from a tracker
    log of a synthetic platform with every error (joint centres off by up to 1 mm, lead +2 %,
    zero offsets, the observation point) gives a configuration whose INI keeps every joint's
    HOME_OFFSET (the drives' reference at the home switches) and speed of the one the log was
    recorded with; each joint's HOME is the corrected commands of the nominal home, so that after
    homing LinuxCNC moves the platform to the [TRAJ] HOME the user expects (the INI says where the
    switches alone leave it); LinuxCNC runs it, and its joints are `hexatwist ik`'s compensated
    commands of the corrected configuration."""
    work = os.path.join(OUT, "calibrated")
    os.makedirs(work, exist_ok=True)
    log = os.path.join(work, "stations.csv")
    corrected = os.path.join(work, "identified.yaml")
    cli("synth", "--stations", "30", "--station-seed", "5", "--joint-errors-mm", "1", "--lead-error-pct", "2",
        "--offsets-mm", "0.5", "--point-offset-mm", "1,-1,2", "--seed", "4", "--out", log)
    cli("identify", "--points", log, "--stations", "30", "--station-seed", "5", "--no-figures", "--out", corrected)
    nominal_ini, ini = cli("linuxcnc").stdout, ini_for(corrected)
    for key in ("HOME_OFFSET", "MAX_VELOCITY"):
        assert ini_values(harness.faster(nominal_ini), key) == ini_values(ini, key), key
    home_world = [0.0, 0.0, 1000 * model_json(corrected)["home_height"], 0.0, 0.0, 0.0]
    home_commands = [1000.0 * leg["command_compensated"] for leg in ik(home_world, corrected)["legs"]]
    joint_homes = [float(v) for v in ini_values(ini, "HOME")[1:]]  # the first is [TRAJ] HOME
    assert ini_values(ini, "HOME")[0] == ini_values(nominal_ini, "HOME")[0]
    assert_close(joint_homes, home_commands, 1e-8, "the joints' HOME")
    assert max(abs(a - float(b)) for a, b in zip(joint_homes, ini_values(ini, "HOME_OFFSET"))) > 0.05
    assert "At the home switches (HOME_OFFSET) this calibrated platform stands at" in ini
    # The corrected platform differs from the nominal one: its commands do (by the joints' errors).
    limits = axis_limits(ini)
    poses = random_inside(random.Random(3), limits, 0.5, corrected, count=6)
    nominal_cmd = [1000.0 * leg["command_compensated"] for leg in ik(poses[0])["legs"]]
    corrected_cmd = [1000.0 * leg["command_compensated"] for leg in ik(poses[0], corrected)["legs"]]
    assert max(abs(a - b) for a, b in zip(nominal_cmd, corrected_cmd)) > 0.05
    steps = [{"home": True}] + [{"mdi": g0(world)} for world in poses]
    run = harness.run(ini, {"steps": steps, "pins": PINS}, timeout=120, keep_dir=os.path.join(work, "run"))
    assert run.results and len(run.results) == len(steps), run.log[-3000:]
    assert all(r["done"] and not r["errors"] for r in run.results), run.results
    # Homed, the platform stands at the nominal home, its joints at their HOME (the switches alone
    # left it 1.2 mm away; the joints' move to HOME ends within 18 nm of it, the pose within 9 nm).
    assert_close(run.results[0]["actual_position"], home_world, 2e-4, "the pose after homing")
    assert_close(run.results[0]["joint_actual_position"], home_commands, 2e-4, "the joints after homing")
    worst_joint, worst_pose = check_pose_steps(run, corrected)
    print("calibrated configuration: worst joint difference %.3g mm, worst FK pose difference %.3g" %
          (worst_joint, worst_pose))


def read_run_csv(path):
    """The rows of a run CSV (stations --out): [t, x, y, z, roll, pitch, yaw] in SI."""
    rows = []
    with open(path) as f:
        next(f)
        for line in f:
            rows.append([float(v) for v in line.split(",")])
    return rows


def rests(rows, shortest):
    """The intervals [t_start, t_end, pose] where the run stands still for at least `shortest` s."""
    out, start = [], 0
    for k in range(1, len(rows) + 1):
        if k == len(rows) or rows[k][1:] != rows[start][1:]:
            if rows[k - 1][0] - rows[start][0] >= shortest:
                out.append((rows[start][0], rows[k - 1][0], rows[start][1:]))
            start = k
    return out


def test_a_station_plan_runs_on_linuxcnc_as_its_gcode_program_with_the_plans_timing():
    """`stations --gcode` (issue 28): the program runs in LinuxCNC, and its joints are the planned
    stations' compensated commands while the plan rests there, at the plan's times (run.csv's)."""
    work = os.path.join(OUT, "gcode")
    os.makedirs(work, exist_ok=True)
    run_csv, program = os.path.join(work, "run.csv"), os.path.join(work, "run.ngc")
    cli("stations", "--count", "13", "--candidates", "300", "--range", "0.1,5", "--out", run_csv, "--gcode", program)
    rows = read_run_csv(run_csv)
    planned = rests(rows, 0.5)
    assert len(planned) == 15, planned  # home, the 13 stations, home
    home_z = 1000 * model_json()["home_height"]
    ini = ini_for()
    trace_every = 0.01
    run = harness.run(ini, {"steps": [{"home": True}, {"program": program, "trace": trace_every}], "pins": []},
                      timeout=150, keep_dir=os.path.join(work, "run"))
    assert run.results and len(run.results) == 2, run.log[-3000:]
    assert all(r["done"] and not r["errors"] for r in run.results), run.results
    trace = run.results[1]["trace"]
    assert trace and trace[-1][0] > rows[-1][0] * 0.9, "the trace does not cover the program"
    # LinuxCNC's rests: the commanded joints unchanged for 0.3 s or more, on its clock (from AUTO_RUN).
    observed, first = [], 0
    for k in range(1, len(trace) + 1):
        if k == len(trace) or max(abs(a - b) for a, b in zip(trace[k][1:], trace[first][1:])) > 1e-9:
            if trace[k - 1][0] - trace[first][0] >= 0.3:
                observed.append((trace[first][0], trace[k - 1][0], trace[first][1:]))
            first = k
    assert len(observed) == len(planned), (len(observed), len(planned))
    # Each rest is the planned station's: the joints are its compensated command.
    worst_joint = 0.0
    for (t_plan, _, pose), (_, _, joints) in zip(planned, observed):
        world = [1000 * pose[0], 1000 * pose[1], home_z + 1000 * pose[2]] + [math.degrees(v) for v in pose[3:]]
        command = [1000.0 * leg["command_compensated"] for leg in ik(world)["legs"]]
        worst_joint = max(worst_joint, assert_close(joints, command, JOINT_TOL_MM, "joints at rest, t = %.3f s" % t_plan))
    # ... at the plan's times: LinuxCNC's arrivals against the plan's, on a clock of its own (an
    # offset, the program's start, and a rate: each dwell and move ends on a task cycle).
    xs, ys = [p[0] for p in planned[1:]], [o[0] for o in observed[1:]]
    n, mx, my = len(xs), sum(xs) / len(xs), sum(ys) / len(ys)
    rate = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    offset = my - rate * mx
    worst = max(abs(y - offset - rate * x) for x, y in zip(xs, ys))
    print("gcode: %d stations over %.1f s; joints at rest within %.3g mm of the plan's commands; LinuxCNC's arrivals "
          "= %.4f s + %.5f x the plan's, within %.3f s" % (n - 1, rows[-1][0], worst_joint, offset, rate, worst))
    assert abs(rate - 1.0) < 0.02 and -0.1 < offset < 1.0 and worst < 0.05, (offset, rate, worst)


def test_warm_legs_read_from_the_temperature_pins_are_compensated_and_seen_by_the_forward_kinematics():
    """Issue 27: a configuration whose legs expand gets a temperature pin per leg (at the reference
    until set). LinuxCNC's joints are `hexatwist ik --temperature-c` of the pins' values and its FK
    pose the commanded one, at rest while the legs warm too (the joints follow the pins); a pin
    outside -60..200 degC stops the machine where it stands."""
    work = os.path.join(OUT, "warm")
    os.makedirs(work, exist_ok=True)
    config = os.path.join(work, "warm.yaml")
    with open(os.path.join(HERE, "..", "..", "..", "configs", "seed.yaml")) as f:
        seed = f.read()
    with open(config, "w") as f:
        f.write(seed + "\nleg_effects:\n  stiffness: 2.0e8\n  length_expansion: 11.5e-6\n"
                "  lead_expansion: 11.0e-6\n  reference_temperature: 20\n")
    home_z = 1000 * model_json(config)["home_height"]
    warm = [24.0, 26.0, 21.5, 30.0, 19.0, 23.0]
    temperature_pins = ["hexatwistkins.leg.%d.temperature" % i for i in range(1, 7)]
    first, second = [40, -20, home_z + 60, 3, -2, 10], [-30, 25, home_z - 40, -2, 4, -15]
    steps = [{"home": True}, {"mdi": g0(first)}, {"setp": dict(zip(temperature_pins, warm))}, {"mdi": g0(second)},
             {"setp": {temperature_pins[0]: 250.0}, "expect_off": True}]
    ini = ini_for(config)
    assert "hexatwistkins.leg.N.temperature [degC], at 20 degC" in ini, "the INI names the pins"
    run = harness.run(ini, {"steps": steps, "pins": PINS + temperature_pins}, timeout=120,
                      keep_dir=os.path.join(work, "run"))
    assert run.results and len(run.results) == len(steps), run.log[-3000:]
    at_first, warmed, at_second, hot = run.results[1:]
    # Until set, the pins hold the reference temperature: the commands are those without expansion.
    assert [at_first["pins"][p] for p in temperature_pins] == [20.0] * 6
    check_pose_steps(harness.LinuxcncRun([at_first], "", 0), config)
    # Warmed at rest: motion computes the commanded pose's joints every servo period, so that they
    # follow the pins: the warm legs are driven shorter by their growth and the platform holds its
    # pose (the FK of the warm legs, as `hexatwist fk --temperature-c` computes it, is the pose).
    held = [1000.0 * leg["command_compensated"] for leg in ik(first, config, warm)["legs"]]
    assert_close(warmed["joint_actual_position"], held, JOINT_TOL_MM, "joints of the held pose, warm")
    assert_close(warmed["actual_position"], first, POSE_TOL, "FK pose while warming")
    assert_close(fk(warmed["joint_actual_position"], config, warm), first, POSE_TOL, "hexatwist fk of the warm joints")
    moved = max(a - b for a, b in zip(at_first["joint_actual_position"], warmed["joint_actual_position"]))
    assert 0.02 < moved < 0.5, moved
    # A move with warm legs: the joints are the warm legs' compensated commands, the FK pose the
    # commanded pose.
    assert at_second["done"] and not at_second["errors"], at_second
    command = [1000.0 * leg["command_compensated"] for leg in ik(second, config, warm)["legs"]]
    cold = [1000.0 * leg["command_compensated"] for leg in ik(second, config)["legs"]]
    worst = assert_close(at_second["joint_actual_position"], command, JOINT_TOL_MM, "warm joints")
    for c, w, t in zip(cold, command, warm):  # a warm leg is commanded shorter, a cool one longer
        assert (c - w) * (t - 20.0) > 0 and abs(c - w) > 0.005 * abs(t - 20.0), (c, w, t)
    assert_close(at_second["actual_position"], second, POSE_TOL, "FK pose after the warm move")
    # 250 degC is no temperature a leg can have: both kinematics refuse it (status 100), and LinuxCNC
    # stops as on any failure of the inverse kinematics: the machine off, the joints where they were.
    assert hot["pins"]["hexatwistkins.ik-status"] == 100 and hot["pins"]["hexatwistkins.fk-status"] == 100, hot["pins"]
    assert hot["pins"]["hexatwistkins.fk-fail"]
    assert any("kinematicsInverse" in e for e in hot["errors"]), hot["errors"]
    assert hot["task_state"] != 4, "the machine is no longer on (linuxcnc.STATE_ON)"
    assert_close(hot["joint_actual_position"], at_second["joint_actual_position"], 1e-12, "joints after the refusal")
    print("warm legs: joints within %.3g mm of hexatwist ik --temperature-c; warming at rest shortened the joints "
          "by up to %.4f mm, the pose held" % (worst, moved))


def test_legs_with_play_are_left_to_linuxcncs_backlash_compensation():
    """Issue 27/28: a configuration whose legs have play (what identify writes) runs on LinuxCNC
    unchanged: `hexatwist linuxcnc` loads the module with play=backlash and gives each joint its
    BACKLASH (the play in motor-side length); the module's kinematics are those of the legs without
    the play, and LinuxCNC's motor commands carry half the play on the side of each joint's last
    motion. Without play=backlash the module refuses the file, naming both settings."""
    work = os.path.join(OUT, "play")
    os.makedirs(work, exist_ok=True)
    with open(os.path.join(HERE, "..", "..", "..", "configs", "seed.yaml")) as f:
        seed = f.read()
    config, rigid = os.path.join(work, "play.yaml"), os.path.join(work, "rigid.yaml")
    with open(config, "w") as f:
        f.write(seed + "\nleg_effects:\n  play: 50.0e-6\n  stiffness: 2.0e8\n")
    with open(rigid, "w") as f:
        f.write(seed + "\nleg_effects:\n  stiffness: 2.0e8\n")
    ini = ini_for(config)
    assert " play=backlash" in ini and ini.count("BACKLASH = 0.050000000") == 6, ini
    home_z = 1000 * model_json(config)["home_height"]
    up, down = [20, -10, home_z + 50, 2, -1, 5], [20, -10, home_z - 30, 2, -1, 5]
    motor_pins = ["joint.%d.motor-pos-cmd" % i for i in range(6)]
    steps = [{"home": True}, {"mdi": g0(up)}, {"mdi": g0(down)}]
    run = harness.run(ini, {"steps": steps, "pins": PINS + motor_pins}, timeout=120,
                      keep_dir=os.path.join(work, "run"))
    assert run.results and len(run.results) == len(steps), run.log[-3000:]
    # The joints are the commands of the legs without play: `hexatwist ik` of the file without it.
    check_pose_steps(harness.LinuxcncRun(run.results[1:], "", 0), rigid)
    # LinuxCNC adds half the play on the side of each joint's last motion (its motor positions
    # count from the home switches: motor = joint - HOME_OFFSET + the backlash correction).
    home_offset = [float(v) for v in ini_values(ini, "HOME_OFFSET")]
    sides = set()
    for before, after in zip(run.results[:-1], run.results[1:]):
        for i in range(6):
            moved = after["joint_actual_position"][i] - before["joint_actual_position"][i]
            extra = after["pins"][motor_pins[i]] - after["joint_actual_position"][i] + home_offset[i]
            assert abs(moved) > 1.0 and abs(extra - math.copysign(0.025, moved)) < 1e-9, (after["step"], i, moved, extra)
            sides.add(moved > 0)
    assert sides == {True, False}, "both directions met"
    refused = harness.run(ini.replace(" play=backlash", ""), {"steps": [{"home": True}], "pins": []}, timeout=60)
    assert refused.results is None and refused.returncode != 0
    assert "its legs have play (leg_effects.play): load with play=backlash" in refused.log, refused.log[-2000:]
