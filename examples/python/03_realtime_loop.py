# SPDX-License-Identifier: BSD-3-Clause
"""The real-time command stream from Python: a 1 kHz loop that takes the pose a motion cue asks for,
gets six checked, rate-limited motor commands from hexatwist.Stream, and counts what it did (the twin of
examples/03_realtime_loop.cpp: the same cue and settings, so the same commands).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/03_realtime_loop.py [SECONDS]

Python is no real-time language (the interpreter and its garbage collector pause): the loop keeps its
deadlines on an idle machine and says how often it did not. A servo thread belongs in C++.
"""
import math
import sys
import time

import numpy as np

import hexatwist

PERIOD = 1e-3  # [s]: 1 kHz


def cue(tick: int) -> list[float]:
    """The motion cue: heave and yaw sines, with one corrupted sample (as a lost packet might give)."""
    t = 1e-3 * tick
    z = 0.08 * math.sin(2 * math.pi * 0.5 * t)
    yaw = math.radians(10) * math.sin(2 * math.pi * 0.3 * t)
    return [math.nan if tick == 700 else 0.0, 0.0, z, 0.0, 0.0, yaw]


seconds = float(sys.argv[1]) if len(sys.argv) > 1 else 2.0
ticks = int(seconds * 1000.0)
if ticks <= 0:
    sys.exit("usage: 03_realtime_loop.py [SECONDS > 0]")

# ----- set-up -----
model = hexatwist.default_model()
stream = hexatwist.Stream(model, strategy="compensated", on_reject="hold", period=PERIOD, max_velocity=0.3,
                          max_acceleration=3.0)  # [m/s, m/s^2] per leg
stream.start(np.zeros(6))  # the platform is parked at home

# ----- the loop -----
overruns = held = rejected = bad = limited = 0
compute = np.empty(ticks)
command = np.zeros(6)
next_tick = time.perf_counter()
for k in range(ticks):
    next_tick += PERIOD
    time.sleep(max(0.0, next_tick - time.perf_counter()))
    woke = time.perf_counter()
    out = stream.pose(cue(k))
    if out.command is not None:  # "new" or "held": hand it to the drives
        command = out.command
        bad += not bool(np.isfinite(command).all())
    rejected += out.status != "ok"
    held += out.action == "held"
    limited += out.rate_limited
    done = time.perf_counter()
    compute[k] = done - woke
    overruns += done - next_tick > PERIOD  # the commands must be out before the next period starts

# ----- report -----
print(f"{ticks} ticks at 1 kHz (Python, time.sleep)")
print(f"compute per tick: median {1e6 * np.median(compute):.1f} us, p99.9 {1e6 * np.quantile(compute, 0.999):.1f} us,"
      f" max {1e6 * compute.max():.1f} us")
print(f"deadline overruns: {overruns}; rejected cues: {rejected} (held: {held}); rate-limited ticks: {limited}; "
      f"leg 1 ends at {command[0]:.6f} m")
# The corrupted cue must have been rejected and held; no command may be non-finite. Overruns are
# reported, not failed: on a shared machine they say more about the machine than the code.
sys.exit(0 if bad == 0 and rejected == 1 and held == 1 else 1)
