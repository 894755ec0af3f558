# SPDX-License-Identifier: BSD-3-Clause
"""Quick start: compensated motor commands for a pose, and the pose they really produce (the twin of
examples/01_compensate.cpp: the same calls of the library, the same lines printed).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/01_compensate.py
"""
import sys

import numpy as np

import hexatwist

model = hexatwist.default_model()  # the seed platform, lead 10 mm (configs/seed.yaml)
pose = np.array([0.0, 0.0, 0.1, 0.0, 0.0, np.deg2rad(30)])  # x, y, z [m], roll, pitch, yaw [rad] from home

# Where does the platform really go? Twist-aware forward kinematics from the motor side.
wanted = hexatwist.platform_points(model, pose)  # point "A" on the platform edge where it should be [m, B]
strategies: tuple[hexatwist.Strategy, ...] = ("conventional", "compensated")
for strategy in strategies:
    try:
        command = hexatwist.motor_command(model, pose, strategy)  # motor-side lengths [m], limits checked
    except hexatwist.StatusError as e:  # names the leg (1 to 6) and the limit
        print(e)
        sys.exit(1)
    fk = hexatwist.forward(model, command)  # from home, the twist included
    if fk.status != hexatwist.Status.OK:
        sys.exit(2)
    miss = float(np.linalg.norm(hexatwist.platform_points(model, fk.poses) - wanted))
    print(f"{strategy:<12}  leg 1 command {command[0]:.6f} m   point A misses by {1e3 * miss:.4f} mm")
