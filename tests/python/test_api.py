# SPDX-License-Identifier: BSD-3-Clause
"""Model construction, YAML and pickling; errors; no copies; the GIL released."""
import os
import pickle
import threading
import time

import numpy as np
import pytest

import hexatwist
from conftest import random_poses


def same_model(a, b, poses):
    ra, rb = hexatwist.commands(a, poses), hexatwist.commands(b, poses)
    return np.array_equal(ra.status, rb.status) and np.array_equal(ra.commands, rb.commands, equal_nan=True)


def test_pickle_round_trip_is_exact(model, poses):
    m = hexatwist.Model.from_arrays(model.base, model.platform, model.base_axes, model.platform_axes,
                                    model.home_height, lead=[0.01, 0.012, 0.01, 0.01, 0.008, 0.01], thread_hand="left",
                                    length_offsets=[1e-4, 0, -2e-4, 0, 0, 3e-5], length_min=1.4, length_max=2.45,
                                    bend_max=0.7, singularity_margin=0.08, observation_point=[1.2, 0, 0], name="odd")
    for original in (model, m):
        copy = pickle.loads(pickle.dumps(original, protocol=pickle.HIGHEST_PROTOCOL))
        assert copy.name == original.name and np.array_equal(copy.lead, original.lead)
        assert copy.thread_hands == original.thread_hands and copy.limits == original.limits
        assert same_model(copy, original, poses[:2000])
    r = hexatwist.commands(model, poses[:100])
    assert np.array_equal(pickle.loads(pickle.dumps(r)).commands, r.commands, equal_nan=True)


def test_model_from_arrays_equals_the_seed(model, poses):
    m = hexatwist.Model.from_arrays(model.base, model.platform, model.base_axes, model.platform_axes,
                                    model.home_height, lead=0.010, length_min=1.40, length_max=2.45,
                                    bend_max=np.deg2rad(40), singularity_margin=np.deg2rad(5),
                                    observation_point=model.observation_point)
    np.testing.assert_array_equal(m.length_home, model.length_home)
    r1, r2 = hexatwist.commands(m, poses), hexatwist.commands(model, poses)
    np.testing.assert_array_equal(r1.commands[r1.ok & r2.ok], r2.commands[r1.ok & r2.ok])


def test_yaml_round_trip(model, poses, tmp_path):
    text = model.to_yaml()
    again = hexatwist.load_model(text)
    assert again.to_yaml() == text
    np.testing.assert_array_equal(again.base, model.base)
    np.testing.assert_array_equal(again.platform_axes, model.platform_axes)
    assert again.lead.tolist() == model.lead.tolist()
    path = tmp_path / "m.yaml"
    path.write_text(text)
    assert same_model(hexatwist.load_model(path), again, poses[:2000])
    assert same_model(hexatwist.load_model(str(path)), again, poses[:2000])
    seed = os.path.join(os.environ.get("HEXATWIST_SOURCE_DIR", ""), "configs", "seed.yaml")
    if os.path.exists(seed):
        assert same_model(hexatwist.load_model(seed), model, poses[:2000])


def one_line(excinfo):
    msg = str(excinfo.value)
    assert msg and "\n" not in msg, msg
    return msg


BAD = [
    ("shape", lambda m: hexatwist.commands(m, np.zeros((4, 5))), hexatwist.InputError, "(N, 6)"),
    ("ndim", lambda m: hexatwist.commands(m, np.zeros((2, 3, 6))), hexatwist.InputError, "(N, 6)"),
    ("dtype", lambda m: hexatwist.commands(m, np.zeros((4, 6), np.float32)), TypeError, "float64"),
    ("dtype int", lambda m: hexatwist.inverse_kinematics(m, np.zeros((4, 6), np.int64)), TypeError, "float64"),
    ("object", lambda m: hexatwist.twist(m, "abc"), TypeError, "float64"),
    ("nan", lambda m: hexatwist.commands(m, np.array([[0.0] * 6, [0, np.nan, 0, 0, 0, 0]])), ValueError, "row 1"),
    ("inf", lambda m: hexatwist.inverse_kinematics(m, np.array([0, 0, np.inf, 0, 0, 0])), ValueError, "NaN or inf"),
    ("fk nan", lambda m: hexatwist.forward(m, np.full((3, 6), np.nan)), ValueError, "lengths: row 0"),
    ("fk guess", lambda m: hexatwist.forward(m, np.ones((3, 6)), guess=np.zeros((2, 6))), ValueError, "guess"),
    ("strategy", lambda m: hexatwist.commands(m, np.zeros(6), strategy="fast"), ValueError, "strategy"),
    ("kind", lambda m: hexatwist.forward(m, np.ones(6), kind="x"), ValueError, "kind"),
    ("config", lambda m: hexatwist.load_model("name: x\nscrew: {lead: -1}\n"), hexatwist.ConfigError, "<yaml>:"),
    ("config key", lambda m: hexatwist.load_model("nme: x\n"), hexatwist.ConfigError, "unknown key"),
    ("missing file", lambda m: hexatwist.load_model("/no/such/file.yaml"), FileNotFoundError, "cannot open"),
    ("arrays", lambda m: hexatwist.Model.from_arrays(np.zeros((5, 3)), m.platform, m.base_axes, m.platform_axes, 1.5,
                                                      length_min=1, length_max=2, bend_max=1, singularity_margin=0.1),
     ValueError, "base"),
    ("invalid model", lambda m: hexatwist.Model.from_arrays(m.base, m.platform, m.base_axes, m.platform_axes, 1.511,
                                                             length_min=2, length_max=1, bend_max=1,
                                                             singularity_margin=0.1), hexatwist.ConfigError, "length"),
    ("status", lambda m: hexatwist.motor_command(m, [0, 0, 2.0, 0, 0, 0]), hexatwist.StatusError, "stroke_above_max"),
    ("single nan", lambda m: hexatwist.motor_command(m, [0, 0, np.nan, 0, 0, 0]), ValueError, "NaN"),
    ("single short", lambda m: hexatwist.motor_command(m, [0, 0, 0]), ValueError, "6 numbers"),
    ("single 2-d", lambda m: hexatwist.motor_command(m, np.zeros((2, 6))), ValueError, "commands()"),
    ("single text", lambda m: hexatwist.motor_command(m, (0, 0, "z", 0, 0, 0)), ValueError, "field 2"),
    ("stream", lambda m: hexatwist.Stream(m, max_velocity=-1), ValueError, "max_velocity"),
    ("map_batch", lambda m: hexatwist.map_batch("nope", m, np.zeros((2, 6))), ValueError, "unknown function"),
]


@pytest.mark.parametrize("name,call,kind,text", BAD, ids=[b[0] for b in BAD])
def test_bad_input_raises_with_one_line(model, name, call, kind, text):
    with pytest.raises(kind) as e:
        call(model)
    assert text in one_line(e)
    if kind not in (FileNotFoundError,):
        assert isinstance(e.value, hexatwist.Error)


def test_per_pose_outcomes_are_statuses_not_exceptions(model):
    r = hexatwist.commands(model, np.array([[0, 0, 0, 0, 0, 0], [0, 0, 2.0, 0, 0, 0]], dtype=float))
    assert [hexatwist.STATUS_NAMES[s] for s in r.status] == ["ok", "stroke_above_max"]
    assert r.limit_leg[1] >= 0 and r.limit_value[1] > r.limit_bound[1]
    assert np.isnan(r.commands[1]).all()
    assert hexatwist.Status(r.status[1]) == hexatwist.Status.STROKE_ABOVE_MAX


def test_contiguous_input_is_never_copied(model, poses):
    view = poses[:5000].view()  # a read-only view of the session's array: it cannot be written, nor need be
    view.flags.writeable = False
    ro = np.array(poses[:5000])
    ro.flags.writeable = False
    before = hexatwist._input_copies()
    for f in (hexatwist.commands, hexatwist.inverse_kinematics, hexatwist.twist):
        f(model, view)
        f(model, ro)
    lengths = np.tile(model.length_home, (3, 1))
    lengths.flags.writeable = False
    hexatwist.forward(model, lengths, guess=np.zeros(6))
    assert hexatwist._input_copies() == before
    # A strided view is copied once (and counted): the counter does see copies.
    hexatwist.commands(model, np.asfortranarray(poses[:100]))
    assert hexatwist._input_copies() == before + 1


def test_gil_is_released_two_threads_overlap(model):
    q = random_poses(400_000, seed=11)
    hexatwist.commands(model, q)  # warm up
    busy = {"n": 0}
    stop = threading.Event()

    def spin():  # pure Python: runs only while the batch call does not hold the GIL
        while not stop.is_set():
            busy["n"] += 1

    t = threading.Thread(target=spin)
    t0 = time.perf_counter()
    hexatwist.commands(model, q)
    alone = time.perf_counter() - t0
    t.start()
    time.sleep(0.01)
    n0 = busy["n"]
    t0 = time.perf_counter()
    hexatwist.commands(model, q)
    during = time.perf_counter() - t0
    n1 = busy["n"]
    stop.set()
    t.join()
    # The Python thread kept running during the batch call (it would be frozen if the GIL were held).
    assert n1 - n0 > 1000, (n1 - n0, alone, during)
