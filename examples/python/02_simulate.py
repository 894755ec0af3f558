# SPDX-License-Identifier: BSD-3-Clause
"""The servo simulation from Python: a yaw sweep of +-10 deg on the seed rig, closed loop, with the
conventional and the compensated commands, and the error of point A (the twin of
examples/02_simulate.cpp: the same lines printed).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/02_simulate.py
"""
import sys

import numpy as np

import hexatwist

rig = hexatwist.Rig()  # platform + servo + load + rates (configs/seed.yaml), built once

# Home -> +10 deg -> -10 deg -> home about z, jerk-limited, sampled at the control rate.
sweep = hexatwist.sweep_trajectory(5, np.deg2rad(10), velocity=np.deg2rad(15), acceleration=np.deg2rad(45),
                                   jerk=np.deg2rad(180), dwell=0.2, dt=rig.control_period)
duration = sweep.dt * (len(sweep.poses) - 1)
strategies: tuple[hexatwist.Strategy, ...] = ("conventional", "compensated")
for strategy in strategies:
    run = hexatwist.simulate(rig, poses=sweep.poses, strategy=strategy)  # one sample per 1 ms tick
    s = run.summary
    if s.status != "ok":  # a limit, the motor speed or the holding torque: when, and which leg
        print(f"t = {s.time:.3f} s, leg {s.leg}: {hexatwist.describe_status(hexatwist.Status[s.status.upper()])}")
        sys.exit(1)
    print(f"{strategy:<12}  {duration:.2f} s simulated: point A misses by up to {1e3 * run.error.max():.4f} mm "
          f"(with perfect servos {1e3 * run.error_twist_only.max():.1e} mm)")
