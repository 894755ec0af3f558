"""Benchmarks of the Python package: median (and worst) of repetitions.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_python.py [--reps 15]

Measures 10^6 compensated commands from an (N, 6) array (targets: <= 0.1 s on two cores), one pose
through motor_command (target: <= 2 us of overhead over the library's own call), and 10^6 motor-side
forward kinematics, warm-started along a path.
"""
import argparse
import statistics
import time

import numpy as np

import hexatwist


def timed(f, reps):
    f()
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), max(times)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--reps", type=int, default=15)
    ap.add_argument("--n", type=int, default=1_000_000)
    a = ap.parse_args()
    m = hexatwist.default_model()
    rng = np.random.default_rng(1)
    q = rng.uniform(-1, 1, (a.n, 6)) * [0.2, 0.2, 0.2, 0.15, 0.15, 0.15]
    ok = hexatwist.commands(m, q).ok.mean()
    med, worst = timed(lambda: hexatwist.commands(m, q, strategy="compensated"), a.reps)
    print(f"commands, {a.n} poses ({100 * ok:.1f}% inside limits): median {med * 1e3:.1f} ms, worst {worst * 1e3:.1f} ms"
          f" ({med / a.n * 1e9:.0f} ns/pose)")
    pose = [0.1, -0.05, 0.1, 0.05, -0.02, 0.1]
    arr = np.array(pose)
    k = 20000
    for name, p in (("list", pose), ("array", arr)):
        med, worst = timed(lambda: [hexatwist.motor_command(m, p) for _ in range(k)], max(5, a.reps // 3))
        print(f"motor_command, one pose ({name}): median {med / k * 1e6:.2f} us per call, worst {worst / k * 1e6:.2f} us")
    one = arr.reshape(1, 6)
    med, _ = timed(lambda: [hexatwist.commands(m, one) for _ in range(k)], max(5, a.reps // 3))
    print(f"commands, a (1, 6) batch: median {med / k * 1e6:.2f} us per call")
    path = np.linspace(0, 1, a.n)[:, None] * np.array([0.2, -0.1, 0.25, 0.1, -0.15, 0.3])
    lengths = hexatwist.commands(m, path).commands
    med, worst = timed(lambda: hexatwist.forward(m, lengths), max(3, a.reps // 5))
    print(f"forward (motor, warm-started), {a.n} poses: median {med * 1e3:.0f} ms, worst {worst * 1e3:.0f} ms")


if __name__ == "__main__":
    main()
