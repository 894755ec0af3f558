# SPDX-License-Identifier: BSD-3-Clause
"""The paper's Rz test (rotation about z, +-30 deg) from hexatwist.study: the observation error with the
conventional and the compensated commands, what the twist and the servos each leave, and the twist of
leg 1. The twin of examples/05_study.cpp: the same numbers, the same lines printed.

    PYTHONPATH=build/python MPLBACKEND=Agg /usr/bin/python3 examples/python/05_study.py [out_dir]
"""
import os
import sys

import matplotlib.pyplot as plt
import numpy as np

import hexatwist

out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
rig = hexatwist.Rig()  # the seed rig and its study section
s = hexatwist.study(rig, test="Rz")
summary = s.summary
if summary.conventional is None or summary.compensated is None:  # a limit stopped a run: where, which leg
    sys.exit(f"t = {summary.time:.3f} s, leg {summary.leg}: {summary.status}")
conv, comp = s.conventional, s.compensated
print(f"Rz test: {len(comp.time)} ticks, {rig.control_period * (len(comp.time) - 1):.2f} s")
for name, r in (("conventional", summary.conventional), ("compensated", summary.compensated)):
    print(f"{name:<12}  max {1e3 * r.total.max:.4f} mm, rms {1e3 * r.total.rms:.4f} mm; twist alone "
          f"{1e3 * r.twist_only.max:.4f} mm, servos alone {1e3 * r.tracking_only.max:.4f} mm; largest torque "
          f"{r.max_torque:.2f} N m")

fig, (a, b) = plt.subplots(2, 1, figsize=(9, 7), sharex=True, constrained_layout=True)
a.plot(conv.time, 1e3 * conv.error, label=f"conventional (max {1e3 * summary.conventional.total.max:.3f} mm)")
a.plot(comp.time, 1e3 * comp.error, label=f"compensated (max {1e3 * summary.compensated.total.max:.3f} mm)")
a.plot(conv.time, 1e3 * s.tracking_only, "--", lw=0.8, label="servo tracking only (no twist)")
a.set(ylabel="observation error [mm]", title="Rz test: rotation about z through +-30 deg")
a.legend()
b.plot(comp.time, np.rad2deg(comp.twist[:, 0]), label="leg 1 twist")
b.plot(comp.time, np.rad2deg(comp.desired[:, 5]), label="yaw commanded")
b.set(xlabel="time [s]", ylabel="[deg]")
b.legend()
path = os.path.join(out_dir, "python_05_study.png")
fig.savefig(path, dpi=80)
print(path)
