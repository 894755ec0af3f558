# SPDX-License-Identifier: BSD-3-Clause
"""Benchmarks of the Python package: median (and worst) of repetitions.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_python.py [--reps 15] [--baseline DIR]

Measures, in one run: 10^6 compensated commands from an (N, 6) array on two threads and on one
(the poses across the SIMD lanes, batch.hpp; target: <= 25 ms on two cores), the same computation in
plain numpy (bench/python/numpy_commands.py, checked against the library first), inverse kinematics
in full and lengths only, one pose through motor_command (target: <= 2 us of overhead over the
library's own call), and 10^6 motor-side forward kinematics, warm-started along a path. With
--baseline DIR (the build/python of another build, e.g. an earlier commit's), the same commands and
inverse kinematics of that build are timed in a subprocess in the same run, for the ratios. Times are
wall-clock medians; "cpu" is the process's CPU time (both threads), which a busy machine inflates less.
"""
import argparse
import os
import statistics
import subprocess
import sys
import time

import numpy as np

import hexatwist

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy_commands  # noqa: E402


def timed(f, reps):
    """(median, worst) wall time and the median CPU time of the process [s]."""
    f()
    times, cpu = [], []
    for _ in range(reps):
        t0, c0 = time.perf_counter(), time.process_time()
        f()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return statistics.median(times), max(times), statistics.median(cpu)


def ms(t):
    return f"median {t[0] * 1e3:.1f} ms, worst {t[1] * 1e3:.1f} ms (cpu {t[2] * 1e3:.1f} ms)"


# Run by --baseline in a subprocess with the other build on sys.path: the same poses, the same calls.
BASELINE = """
import sys, time, statistics, numpy as np, hexatwist
n, reps = int(sys.argv[1]), int(sys.argv[2])
m = hexatwist.default_model()
q = np.random.default_rng(1).uniform(-1, 1, (n, 6)) * [0.2, 0.2, 0.2, 0.15, 0.15, 0.15]
def timed(f, reps):
    f()
    t, c = [], []
    for _ in range(reps):
        t0, c0 = time.perf_counter(), time.process_time(); f()
        t.append(time.perf_counter() - t0); c.append(time.process_time() - c0)
    return statistics.median(t), max(t), statistics.median(c)
for threads in (2, 1):
    hexatwist.set_num_threads(threads)
    print("commands", threads, *timed(lambda: hexatwist.commands(m, q), reps))
    print("inverse_kinematics", threads, *timed(lambda: hexatwist.inverse_kinematics(m, q), max(3, reps // 3)))
"""


def baseline(path, n, reps):
    env = dict(os.environ, PYTHONPATH=path)
    out = subprocess.run([sys.executable, "-c", BASELINE, str(n), str(reps)], env=env, check=True,
                         capture_output=True, text=True).stdout
    return {(f, int(t)): (float(a), float(b), float(c)) for f, t, a, b, c in (line.split() for line in out.splitlines())}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=15)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--baseline", help="build/python of another build to time beside this one")
    a = ap.parse_args()
    m = hexatwist.default_model()
    rng = np.random.default_rng(1)
    q = rng.uniform(-1, 1, (a.n, 6)) * [0.2, 0.2, 0.2, 0.15, 0.15, 0.15]
    r = hexatwist.commands(m, q)
    print(f"{a.n} poses, {100 * r.ok.mean():.2f}% inside every limit; load average {os.getloadavg()[0]:.1f} "
          f"on {os.cpu_count()} CPUs")
    # The numpy version decides and computes alike: checked before it is timed.
    nm = numpy_commands.NumpyModel(m)
    c, accepted = numpy_commands.compensated_commands_chunked(nm, q)
    agree = (accepted == r.ok).mean()
    diff = np.abs(c[accepted & r.ok] - r.commands[accepted & r.ok]).max()
    print(f"numpy version: the same accept/refuse for {100 * agree:.4f}% of the poses, commands within {diff:.1e} m")
    results = {}
    for threads in (2, 1):
        hexatwist.set_num_threads(threads)
        results[threads] = timed(lambda: hexatwist.commands(m, q, strategy="compensated"), a.reps)
        print(f"commands (compensated), {threads} thread(s): {ms(results[threads])} "
              f"({results[threads][0] / a.n * 1e9:.1f} ns/pose)")
    hexatwist.set_num_threads(2)
    print(f"  second thread: {results[1][0] / results[2][0]:.2f}x")
    t_np = timed(lambda: numpy_commands.compensated_commands_chunked(nm, q), max(3, a.reps // 5))
    print(f"plain numpy, the same computation (blocks of 4096 poses), 1 thread: {ms(t_np)}: "
          f"{t_np[0] / results[2][0]:.0f}x the library on 2 threads")
    for threads in (2, 1):
        hexatwist.set_num_threads(threads)
        ik = timed(lambda: hexatwist.inverse_kinematics(m, q), max(3, a.reps // 3))
        ik_l = timed(lambda: hexatwist.inverse_kinematics(m, q, lengths_only=True), a.reps)
        print(f"inverse_kinematics, {threads} thread(s): full (axes, bends) {ms(ik)}; lengths_only {ms(ik_l)}: "
              f"{ik_l[0] / results[threads][0]:.2f}x commands")
    hexatwist.set_num_threads(2)
    if a.baseline:
        b = baseline(a.baseline, a.n, a.reps)
        for threads in (2, 1):
            c, i = b[("commands", threads)], b[("inverse_kinematics", threads)]
            print(f"baseline {a.baseline}, {threads} thread(s): commands {ms(c)}: {c[0] / results[threads][0]:.2f}x "
                  f"this build's (cpu {c[2] / results[threads][2]:.2f}x); inverse_kinematics {ms(i)}: "
                  f"{i[0] / c[0]:.1f}x its commands")
    pose = [0.1, -0.05, 0.1, 0.05, -0.02, 0.1]
    arr = np.array(pose)
    k = 20000
    for name, p in (("list", pose), ("array", arr)):
        med, worst, _ = timed(lambda: [hexatwist.motor_command(m, p) for _ in range(k)], max(5, a.reps // 3))
        print(f"motor_command, one pose ({name}): median {med / k * 1e6:.2f} us per call, worst {worst / k * 1e6:.2f} us")
    one = arr.reshape(1, 6)
    med, _, _ = timed(lambda: [hexatwist.commands(m, one) for _ in range(k)], max(5, a.reps // 3))
    print(f"commands, a (1, 6) batch: median {med / k * 1e6:.2f} us per call")
    path = np.linspace(0, 1, a.n)[:, None] * np.array([0.2, -0.1, 0.25, 0.1, -0.15, 0.3])
    lengths = hexatwist.commands(m, path).commands
    med, worst, _ = timed(lambda: hexatwist.forward(m, lengths), max(3, a.reps // 5))
    print(f"forward (motor, warm-started), {a.n} poses: median {med * 1e3:.0f} ms, worst {worst * 1e3:.0f} ms")


if __name__ == "__main__":
    main()
