# SPDX-License-Identifier: BSD-3-Clause
"""The Dask helper on a real (local) cluster: a scheduler and two workers on 127.0.0.1, started as
processes and always stopped; results identical, bit for bit, to the local run."""
import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Mapping

import numpy as np
import pytest

import hexatwist
from conftest import random_poses

distributed = pytest.importorskip("distributed")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def client(tmp_path_factory):
    port = free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in [os.path.dirname(os.path.dirname(hexatwist.__file__)),
                                                    os.path.dirname(__file__), env.get("PYTHONPATH", "")] if p)
    log = tmp_path_factory.mktemp("dask")
    procs = []

    def start(args, name):
        out = open(log / f"{name}.log", "w")
        procs.append(subprocess.Popen([sys.executable, "-m", *args], env=env, stdout=out, stderr=subprocess.STDOUT,
                                      start_new_session=True, cwd=log))

    try:
        start(["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard",
               "--idle-timeout", "120s"],  # and should pytest itself be killed, the cluster still ends
              "scheduler")
        for i in range(2):
            start(["distributed.cli.dask_worker", address, "--host", "127.0.0.1", "--nthreads", "1",
                   "--no-dashboard", "--memory-limit", "0", "--name", f"w{i}", "--death-timeout", "30"], f"worker{i}")
        c = distributed.Client(address, timeout=60)
        c.wait_for_workers(2, timeout=60)
        yield c
        c.close()
    finally:
        for p in procs:
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        deadline = time.monotonic() + 10
        for p in procs:
            try:
                p.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()


def test_a_million_pose_map_equals_the_local_run(client, model):
    q = random_poses(1_000_000, seed=5)
    local = hexatwist.commands(model, q)
    remote = hexatwist.map_batch("commands", model, q, client=client, chunk=100_000)
    assert len(client.scheduler_info()["workers"]) == 2
    for key in local:
        assert np.array_equal(local[key], remote[key], equal_nan=True), key
    # Forward kinematics, warm-started along the batch: the same on the cluster's chunks.
    m = local.commands[local.ok][:50_000]
    fl = hexatwist.forward(model, m)
    fr = hexatwist.map_batch("forward", model, m, client=client, chunk=10_000)
    for key in fl:
        assert np.array_equal(fl[key], fr[key], equal_nan=True), key


def test_sixteen_simulations_equal_the_local_run(client):
    dt = hexatwist.control_period()
    t = np.arange(600) * dt
    runs = []
    for i in range(16):
        q = np.zeros((600, 6))
        q[:, i % 6] = 0.01 * np.sin(np.pi * t / t[-1]) ** 2 * (1 + i // 6)
        runs.append(dict(poses=q, strategy="compensated" if i % 2 else "conventional"))
    local = hexatwist.map_simulations(runs)
    remote = hexatwist.map_simulations(runs, client=client)
    assert len(remote) == 16
    for a, b in zip(local, remote):
        assert a.summary == b.summary
        for key in ("time", "actual", "command", "motor", "error", "twist"):
            assert np.array_equal(a[key], b[key]), key


def test_hexatwist_threads_follow_the_workers_and_its_functions_pickle(client):
    # A compiled function shipped to every worker: it pickles, and each --nthreads 1 worker runs one thread.
    assert set(client.run(hexatwist.get_num_threads).values()) == {1}
    assert client.submit(hexatwist.get_num_threads, pure=False).result() == 1


def test_per_row_keyword_arrays_are_cut_with_the_rows(client, model):
    q = random_poses(20_000, seed=8)
    r = hexatwist.commands(model, q)
    m = r.commands[r.ok]
    guess = q[r.ok]  # each row starts at its own pose
    local = hexatwist.forward(model, m, guess=guess)
    remote = hexatwist.map_batch("forward", model, m, client=client, chunk=4096, guess=guess)
    for key in local:
        assert np.array_equal(local[key], remote[key], equal_nan=True), key
    # A single guess for every row stays whole.
    one = hexatwist.map_batch("forward", model, m[:5000], client=client, chunk=4096, guess=guess[0])
    assert np.array_equal(one.poses, hexatwist.forward(model, m[:5000], guess=guess[0]).poses, equal_nan=True)


def same(a, b):
    """Equal numbers, NaN equal to NaN, through nested dicts and typed results."""
    if isinstance(a, Mapping):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if a is None or b is None:  # JSON's null for a number without a value
        return a is None and b is None
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


def test_a_tolerance_study_on_two_workers_equals_the_local_run_bit_for_bit(client, model):
    settings = dict(platforms=120, seed=4, random=150, test_samples=11, sigmas=dict(base_joint=80e-6, lead=1e-4))
    local = hexatwist.tolerance(model, **settings)
    remote = hexatwist.tolerance(model, client=client, chunk=17, **settings)
    for key in local:
        if isinstance(local[key], np.ndarray):
            assert np.array_equal(local[key], remote[key], equal_nan=True), key
    assert same(local.summary, remote.summary)
    assert same(local.linear, remote.linear)
    assert len(local.max_point) == 120 and local.summary["failures"] == 0


def test_a_calibrated_tolerance_study_on_two_workers_equals_the_local_run_bit_for_bit(client, model):
    settings = dict(platforms=6, seed=3, random=40, test_samples=5, calibration="stations:30,2",
                    tracker=dict(noise=20e-6, points_per_station=10))
    local = hexatwist.tolerance(model, **settings)
    remote = hexatwist.tolerance(model, client=client, chunk=4, **settings)
    for key in local:
        if isinstance(local[key], np.ndarray):
            assert np.array_equal(local[key], remote[key], equal_nan=True), key
    assert same(local.summary, remote.summary)
    assert same(local.linear, remote.linear)
    assert np.all(local.calibration == 0)


def test_a_workspace_map_and_volume_on_two_workers_equal_the_local_run_bit_for_bit(client, model):
    orientation = (0.05, -0.1, 0.2)
    local = hexatwist.workspace_map(model, orientation, spacing=0.04)
    remote = hexatwist.workspace_map(model, orientation, spacing=0.04, client=client, chunk=3)
    for key in local:
        if isinstance(local[key], np.ndarray):
            assert np.array_equal(local[key], remote[key], equal_nan=True), key
    assert local.grid == remote.grid
    v_local = hexatwist.workspace_volume(model, orientation, cell=0.05)
    v_remote = hexatwist.workspace_volume(model, orientation, cell=0.05, client=client, chunk=50)
    assert (v_local.volume, v_local.error, v_local.coarse_volume) == (v_remote.volume, v_remote.error, v_remote.coarse_volume)


@pytest.mark.skipif(not os.environ.get("HEXATWIST_CLI"), reason="the command-line tool is not built")
def test_the_command_line_on_the_cluster_equals_its_local_run(client, tmp_path):
    # hexatwist tolerance / workspace --scheduler: the samples on the workers, the report the same.
    import json

    cli = os.environ["HEXATWIST_CLI"]
    scheduler = client.scheduler.address
    env = dict(os.environ, HEXATWIST_PYTHON=sys.executable,
               PYTHONPATH=os.pathsep.join(p for p in [os.path.dirname(os.path.dirname(hexatwist.__file__)),
                                                      os.environ.get("PYTHONPATH", "")] if p))

    def run(*args):
        r = subprocess.run([cli, *args], env=env, capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        return json.loads(r.stdout)

    common = ["--platforms", "60", "--workspace", "random=80,samples=5", "--json", "--no-figures"]
    local = run("tolerance", *common, "--out", str(tmp_path / "tl"))
    remote = run("tolerance", *common, "--out", str(tmp_path / "tr"), "--scheduler", scheduler)
    assert remote["cluster"]["workers"] == 2
    for key in ("monte_carlo", "linearised", "worst_per_platform", "failures"):
        assert same(local[key], remote[key]), key
    assert (tmp_path / "tl" / "platforms.csv").read_text() == (tmp_path / "tr" / "platforms.csv").read_text()
    common = ["--platforms", "4", "--workspace", "random=30,samples=5", "--json", "--no-figures",
              "--calibration", "stations:30", "--tracker-noise-um", "20"]
    local = run("tolerance", *common, "--out", str(tmp_path / "cl"))
    remote = run("tolerance", *common, "--out", str(tmp_path / "cr"), "--scheduler", scheduler)
    for key in ("monte_carlo", "linearised", "worst_per_platform", "failures"):
        assert same(local[key], remote[key]), key
    assert local["tracker"] == remote["tracker"] and local["tracker"]["noise"] == 20e-6
    assert (tmp_path / "cl" / "platforms.csv").read_text() == (tmp_path / "cr" / "platforms.csv").read_text()
    common = ["--heights", "0", "--spacing", "0.05", "--map-spacing", "0.05", "--yaws", "0", "--json", "--no-figures"]
    local = run("workspace", *common, "--out", str(tmp_path / "wl"))
    remote = run("workspace", *common, "--out", str(tmp_path / "wr"), "--scheduler", scheduler)
    assert (local["volume"], local["volume_error"]) == (remote["volume"], remote["volume_error"])
    assert (tmp_path / "wl" / "map.csv").read_text() == (tmp_path / "wr" / "map.csv").read_text()
