# SPDX-License-Identifier: BSD-3-Clause
"""The package's types against what it does (issue 24): the stub of the compiled core (_hexatwist.pyi)
names every function, class, method, property and constant the module has, and nothing else, with the
same parameters (mypy's stubtest, and the signatures pybind11 states); every public function of every
subsystem module is in its __all__, fully annotated, and re-exported by hexatwist; and the results of
every public function hold, field by field, the types their annotations state (dtype of every array,
Literal values, nested results), are frozen and pickle."""
import ast
import dataclasses
import inspect
import os
import pickle
import re
import subprocess
import sys
import types
import typing

import numpy as np
import pytest

import hexatwist
from hexatwist import _hexatwist as core

HERE = os.path.dirname(os.path.abspath(__file__))
PACKAGE = os.path.dirname(hexatwist.__file__)
MODULES = [hexatwist.core, hexatwist.kinematics, hexatwist.motion, hexatwist.dynamics, hexatwist.simulation,
           hexatwist.calibration, hexatwist.design, hexatwist.io, hexatwist.distributed]


# ---- the stub of the compiled core ------------------------------------------------------------------


def stub_tree():
    with open(os.path.join(PACKAGE, "_hexatwist.pyi")) as f:
        return ast.parse(f.read())


def stub_names(body):
    """Functions (name -> ast node), classes (name -> body) and annotated names of a stub body."""
    functions, classes, names = {}, {}, set()
    for node in body:
        if isinstance(node, ast.FunctionDef):
            functions[node.name] = node
        elif isinstance(node, ast.ClassDef):
            classes[node.name] = node.body
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names.add(node.target.id)
    return functions, classes, names


def test_mypy_stubtest_finds_the_stub_and_the_compiled_module_alike():
    env = dict(os.environ, MYPYPATH=os.path.dirname(PACKAGE), PYTHONPATH=os.path.dirname(PACKAGE))
    r = subprocess.run([sys.executable, "-m", "mypy.stubtest", "hexatwist._hexatwist", "--mypy-config-file",
                        os.path.join(HERE, "mypy.ini"), "--allowlist", os.path.join(HERE, "stubtest_allowlist.txt")],
                       env=env, capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, r.stdout + r.stderr


def runtime_members(owner):
    return {n for n in vars(owner) if not n.startswith("__") and not n.startswith("_pybind11")}


def test_every_name_of_the_compiled_module_is_in_the_stub_and_back():
    functions, classes, names = stub_names(stub_tree().body)
    runtime = runtime_members(core)
    runtime_classes = {n for n in runtime if isinstance(getattr(core, n), type)}
    runtime_functions = {n for n in runtime if callable(getattr(core, n)) and n not in runtime_classes}
    runtime_constants = runtime - runtime_classes - runtime_functions
    assert set(functions) == runtime_functions, set(functions) ^ runtime_functions
    assert set(classes) == runtime_classes, set(classes) ^ runtime_classes
    assert names - {n for n in names if n.startswith("_")} == runtime_constants
    for name, body in classes.items():
        methods, _, attributes = stub_names(body)
        cls = getattr(core, name)
        if issubclass(cls, BaseException):
            assert set(methods) | attributes <= {"status"}, name
            continue
        members = runtime_members(cls)
        assert set(methods) - {"__init__"} == members, (name, set(methods) ^ members)


def split_parameters(text):
    """The parameters of a pybind11 signature line, split at the commas outside brackets."""
    parts, depth, current = [], 0, ""
    for ch in text:
        depth += ch in "([{"
        depth -= ch in ")]}"
        if ch == "," and depth == 0:
            parts.append(current.strip())
            current = ""
        else:
            current += ch
    return [p for p in parts + [current.strip()] if p]


def runtime_parameters(function, name):
    """[(name, has_default)] and the keyword-only marker of a pybind11 function, from its signature line."""
    first = function.__doc__.splitlines()[0]
    match = re.match(rf"{re.escape(name)}\((.*)\) ->", first)
    assert match, first
    out = []
    for p in split_parameters(match.group(1)):
        if p == "*":
            out.append(("*", False))
        else:
            out.append((p.split(":")[0].strip(), "=" in p))
    return out


def stub_parameters(node):
    a = node.args
    positional = a.posonlyargs + a.args
    defaults = [False] * (len(positional) - len(a.defaults)) + [True] * len(a.defaults)
    out = list(zip([p.arg for p in positional], defaults))
    if a.kwonlyargs:
        out.append(("*", False))
        out += [(p.arg, d is not None) for p, d in zip(a.kwonlyargs, a.kw_defaults)]
    return out


def test_the_stub_states_each_compiled_function_with_its_parameters():
    functions, classes, _ = stub_names(stub_tree().body)
    checked = 0
    for name, node in functions.items():
        assert stub_parameters(node) == runtime_parameters(getattr(core, name), name), name
        checked += 1
    for cls_name, body in classes.items():
        methods, _, _ = stub_names(body)
        for name, node in methods.items():
            if name == "__init__" or any(isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list):
                continue
            attr = getattr(getattr(core, cls_name), name)
            params = stub_parameters(node)
            if not any(isinstance(d, ast.Name) and d.id == "staticmethod" for d in node.decorator_list):
                params = [("self", False)] + params[1:]
            assert params == runtime_parameters(attr, name), (cls_name, name)
            checked += 1
    assert checked > 50


# ---- the subsystem modules ---------------------------------------------------------------------------


@pytest.mark.parametrize("module", MODULES, ids=[m.__name__ for m in MODULES])
def test_each_module_exports_what_it_defines_typed(module):
    for name in module.__all__:
        assert hasattr(module, name), name
    defined = {n for n, v in vars(module).items() if not n.startswith("_") and (inspect.isfunction(v) or
                                                                                 inspect.isclass(v))
               and getattr(v, "__module__", None) == module.__name__}
    assert defined <= set(module.__all__), defined - set(module.__all__)
    for name in module.__all__:
        f = getattr(module, name)
        if not inspect.isfunction(f):
            continue
        hints = typing.get_type_hints(f)
        parameters = [p for p in inspect.signature(f).parameters]
        assert set(parameters) <= set(hints) and "return" in hints, (name, set(parameters) - set(hints))


def test_hexatwist_re_exports_every_subsystem():
    names = [n for m in MODULES for n in m.__all__]
    assert hexatwist.__all__ == names and len(set(names)) == len(names)
    for m in MODULES:
        for n in m.__all__:
            assert getattr(hexatwist, n) is getattr(m, n), n


def test_status_is_the_librarys():
    assert [s.name.lower() for s in hexatwist.Status] == list(hexatwist.STATUS_NAMES)
    assert [int(s) for s in hexatwist.Status] == list(range(len(hexatwist.STATUS_NAMES)))
    assert all(hexatwist.describe_status(s) for s in hexatwist.Status)


# ---- the results against their annotations ----------------------------------------------------------


def mismatch(value, hint, where):
    """Why `value` is not of type `hint` (None if it is)."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if hint is typing.Any:
        return None
    if origin in (typing.Union, types.UnionType):
        reasons = [mismatch(value, a, where) for a in args]
        return None if any(r is None for r in reasons) else f"{where}: {value!r} is none of {hint}"
    if origin is typing.Literal:
        return None if value in args else f"{where}: {value!r} not in {args}"
    if origin is np.ndarray:
        dtype = typing.get_args(args[1])[0]
        if not isinstance(value, np.ndarray) or value.dtype != np.dtype(dtype):
            return f"{where}: {type(value).__name__} {getattr(value, 'dtype', '')} is not an array of {dtype}"
        return None
    if origin is tuple:
        if not isinstance(value, tuple):
            return f"{where}: {type(value).__name__} is not a tuple"
        items = args[:1] * len(value) if len(args) == 2 and args[1] is Ellipsis else args
        if len(items) != len(value):
            return f"{where}: {len(value)} items, expected {len(items)}"
        return next((r for v, a in zip(value, items) if (r := mismatch(v, a, where + "[]"))), None)
    if origin is dict:
        if not isinstance(value, dict):
            return f"{where}: {type(value).__name__} is not a dict"
        return next((r for k, v in value.items() if (r := mismatch(k, args[0], where) or mismatch(v, args[1], where))),
                    None)
    if typing.is_typeddict(hint):
        keys = typing.get_type_hints(hint)
        if not isinstance(value, dict) or set(value) != set(keys):
            return f"{where}: keys {set(value) if isinstance(value, dict) else value} are not {set(keys)}"
        return next((r for k, t in keys.items() if (r := mismatch(value[k], t, f"{where}[{k}]"))), None)
    if hint is float:
        return None if type(value) is float else f"{where}: {type(value).__name__} {value!r} is not a float"
    if hint is int:
        return None if type(value) is int else f"{where}: {type(value).__name__} {value!r} is not an int"
    if isinstance(hint, type):
        if not isinstance(value, hint):
            return f"{where}: {type(value).__name__} is not a {hint.__name__}"
        return check_result(value, where) if isinstance(value, hexatwist.Result) else None
    raise AssertionError(f"{where}: no check for {hint}")


SEEN = set()


def check_result(result, where):
    """Every field of a typed result against its annotation; the classes met are recorded."""
    cls = type(result)
    SEEN.add(cls)
    hints = typing.get_type_hints(cls)
    names = [f.name for f in dataclasses.fields(cls)]
    assert list(result) == names and set(vars(result)) == set(names), (where, set(vars(result)) ^ set(names))
    return next((r for n in names if (r := mismatch(getattr(result, n), hints[n], f"{where}.{n}"))), None)


def calls():
    """One call of every public function that returns a typed result (some twice: ok and refused)."""
    source = os.environ.get("HEXATWIST_SOURCE_DIR", "")
    stations_log = os.path.join(source, "examples", "tracker_stations.csv")
    cue = os.path.join(source, "examples", "motion_simulator.csv")
    if not (os.path.exists(stations_log) and os.path.exists(cue)):
        pytest.skip("HEXATWIST_SOURCE_DIR not set")
    model, rig = hexatwist.default_model(), hexatwist.Rig()
    q = np.array([[0, 0, 0, 0, 0, 0], [0.1, -0.05, 0.2, 0.05, -0.1, 0.2], [0, 0, 2.0, 0, 0, 0]], dtype=float)
    c = hexatwist.commands(model, q)
    stream = hexatwist.Stream(model)
    stream.start(np.zeros(6))
    q_sim = np.zeros((50, 6))
    q_sim[:, 2] = np.linspace(0, 0.002, 50)
    q_far = q_sim.copy()
    q_far[30:, 2] = 2.0
    run = hexatwist.stations_run(rig, count=40, seed=4)
    log = hexatwist.read_point_log(stations_log)
    obs = hexatwist.observations_at_rest(model, run.t, run.poses, log.stamps, log.points, log.targets)
    w = hexatwist.required_workspace(rig, random=30, test_samples=3)
    csv = "t,x,y,z,roll,pitch,yaw\n0,0,0,0,0,0,0\n0.01,0,0,1,0,0,0.5\n0.02,0,0,2,0,0,1\n"
    return {
        "inverse_kinematics": hexatwist.inverse_kinematics(model, q),
        "inverse_kinematics lengths_only": hexatwist.inverse_kinematics(model, q, lengths_only=True),
        "twist": hexatwist.twist(model, q),
        "commands": c,
        "forward": hexatwist.forward(model, c.commands[:2]),
        "forward_kinematics_tracked": hexatwist.forward_kinematics_tracked(model, c.commands[:2]),
        "FkTracker.track": hexatwist.FkTracker(model).track(c.commands[0]),
        "Stream.pose new": stream.pose(q[1]),
        "Stream.pose held": stream.pose(q[2]),
        "Stream.pose none": hexatwist.Stream(model, on_reject="skip").pose(q[2]),
        "axis_range": hexatwist.axis_range(model, "z"),
        "sweep_trajectory": hexatwist.sweep_trajectory(2, 0.01, velocity=0.1, acceleration=1, jerk=10, dwell=0.01,
                                                       dt=1e-3),
        "waypoint_trajectory": hexatwist.waypoint_trajectory(q[:2], velocity=0.1, acceleration=1, jerk=10, dwell=0,
                                                             dt=1e-2),
        "read_trajectory": hexatwist.read_trajectory(csv),
        "resample": hexatwist.resample([0, 1, 2], q, 0.25),
        "platform_motion": hexatwist.platform_motion(q, q, q),
        "inverse_dynamics": hexatwist.inverse_dynamics(rig, q, q, q),
        "size_motors": hexatwist.size_motors(rig, cue),
        "size_motors refused": hexatwist.size_motors(rig, poses=q_far),
        "simulate": hexatwist.simulate(rig, poses=q_sim),
        "simulate refused": hexatwist.simulate(rig, poses=q_far),
        "study": hexatwist.study(rig, poses=q_sim),
        "study refused": hexatwist.study(rig, poses=q_far),
        "study with leg effects": hexatwist.study(
            hexatwist.seed_config_yaml() + "\nleg_effects:\n  play: 30.0e-6\n  length_expansion: 11.5e-6\n",
            poses=q_sim, temperature_rise=1.0),
        "read_point_log": log,
        "measured_test": hexatwist.measured_test(rig, "Rz"),
        "stations_run": run,
        "observations_at_rest": obs,
        "identify": hexatwist.identify(model, obs.motor, obs.points, obs.targets, calibration="basic", folds=2,
                                       accuracy_poses=20),
        "identify refused": hexatwist.identify(model, obs.motor[:20], obs.points[:20], calibration="basic"),
        "plan_stations": hexatwist.plan_stations(rig, count=13, candidates=40, accuracy_poses=20),
        "compare": hexatwist.compare(model, model, stations=6),
        "register_points": hexatwist.register_points(np.eye(3) * 2 + 1, np.eye(3) * 2),
        "required_workspace": w,
        "workspace_volume": hexatwist.workspace_volume(model, cell=0.1, refine=1),
        "workspace_slice": hexatwist.workspace_slice(model, spacing=0.1),
        "orientation_workspace": hexatwist.orientation_workspace(model, torsions=(0.0, 0.2), directions=6),
        "workspace_map": hexatwist.workspace_map(model, spacing=0.1),
        "map_summary": hexatwist.workspace_map(model, spacing=0.1).summary(),
        "map_summary, no node inside": hexatwist.workspace_map(model, offset=0.9, spacing=0.2).summary(),
        "tilt_extremes": hexatwist.orientation_workspace(model, torsions=(0.0, 1.4), directions=6).extremes()[1],
        "design_axes": hexatwist.design_axes(rig, w.poses, volume_samples=100, cell=0.1, grid_step=0.3),
        "tolerance": hexatwist.tolerance(rig, w.poses, platforms=4),
        "target_layouts": hexatwist.target_layouts(rig, w.poses, max_extra=1, calibration="stations:14")[1],
        "map_batch": hexatwist.map_batch("commands", model, q),
        "map_simulations": hexatwist.map_simulations([dict(poses=q_sim)])[0],
    }


@pytest.fixture(scope="module")
def results():
    return calls()


def test_every_result_holds_the_types_its_annotations_state(results):
    for name, result in results.items():
        assert isinstance(result, hexatwist.Result), name
        reason = check_result(result, name)
        assert reason is None, reason
    # Every result class of the package was met, nested ones included.
    classes = {v for m in MODULES for v in vars(m).values()
               if isinstance(v, type) and issubclass(v, hexatwist.Result) and dataclasses.is_dataclass(v)}
    assert classes == SEEN, classes - SEEN


def test_the_refusals_are_statuses_in_their_results(results):
    assert results["size_motors refused"].summary.motors is None
    assert results["simulate refused"].summary.error_max is None
    assert results["study refused"].summary.compensated is None
    assert results["identify refused"].status != "ok" and results["identify refused"].corrected_model is None
    assert results["Stream.pose held"].action == "held" and results["Stream.pose none"].action == "none"
    assert set(results["size_motors"].summary.motors[0].share) == set(hexatwist.TORQUE_TERMS)


def test_results_are_frozen_mappings_that_pickle(results):
    for name, result in results.items():
        again = pickle.loads(pickle.dumps(result))
        assert type(again) is type(result) and list(again) == list(result), name
        for key in result:
            a, b = result[key], again[key]
            if isinstance(a, np.ndarray):
                assert np.array_equal(a, b, equal_nan=True), (name, key)
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(result, next(iter(result)), None)
        assert dict(result).keys() == set(result) and len(result) == len(dataclasses.fields(result))
        with pytest.raises(KeyError):
            result["no such field"]


def test_the_compiled_properties_hold_their_typed_dicts():
    model, rig = hexatwist.default_model(), hexatwist.Rig()
    assert mismatch(model.limits, hexatwist.Limits, "limits") is None
    assert mismatch(rig.servo, hexatwist.ServoSpec, "servo") is None
    assert mismatch(rig.load, hexatwist.LoadSpec, "load") is None
    assert mismatch(rig.mechanism, hexatwist.MechanismSpec, "mechanism") is None
    assert mismatch(model.thread_hands, tuple[str, ...], "thread_hands") is None


def test_the_type_check_itself_refuses_what_does_not_match():
    assert mismatch(np.zeros(3, np.float32), hexatwist.FloatArray, "a") is not None
    assert mismatch(np.zeros(3, np.int64), hexatwist.Int8Array, "a") is not None
    assert mismatch(1, float, "x") is not None and mismatch(1.0, int, "x") is not None
    assert mismatch("hold", typing.Literal["new", "held", "none"], "action") is not None
    assert mismatch((1.0, "x"), tuple[float, ...], "t") is not None
    assert mismatch({"a": 1}, dict[str, float], "d") is not None
    good = hexatwist.commands(hexatwist.default_model(), np.zeros((2, 6)))
    assert check_result(good, "ok") is None
    bad = hexatwist.Commands._of({**dict(good), "limit_leg": good.limit_leg.astype(np.int64)})
    assert "limit_leg" in check_result(bad, "bad")
