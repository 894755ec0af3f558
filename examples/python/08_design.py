# SPDX-License-Identifier: BSD-3-Clause
"""Designing the seed's fixed U-joint axes from Python (docs/theory/design.md §16-18): the workspace's
volume with its stated error, the symmetric turns of the axes that minimise the largest twist over the
required workspace (the study's tests and 2000 random combined poses), and the largest |twist| over the
x-y slice at z = 0 and yaw 15 deg for the seed and for the design, on one colour scale (the same arrays
as `hexatwist workspace` and `hexatwist design`). The twin of examples/08_design.cpp: the same lines
printed.

    PYTHONPATH=build/python MPLBACKEND=Agg /usr/bin/python3 examples/python/08_design.py [out_dir]
"""
import os
import sys

import matplotlib.pyplot as plt
import numpy as np

import hexatwist

out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
rig = hexatwist.Rig()
seed = rig.model
v = hexatwist.workspace_volume(seed)
print(f"workspace volume at home orientation: {v.volume:.4f} m^3 (stated error {v.error:.4f} m^3)")

d = hexatwist.design_axes(rig)  # the study's tests and 2000 random combined poses, symmetric
b, a = d.before, d.after
print(f"largest |twist| over the required workspace ({d.poses} poses): {np.rad2deg(b.max_twist):.2f} deg (leg "
      f"{b.twist_leg}) -> {np.rad2deg(a.max_twist):.2f} deg (leg {a.twist_leg})")
print(f"volume {b.volume:.4f} -> {a.volume:.4f} m^3")
print("turns of ja, jd [deg]:", " ".join(f"{x:+.2f}" for x in np.rad2deg(d.turn_base)), "|",
      " ".join(f"{x:+.2f}" for x in np.rad2deg(d.turn_platform)))

orientation = (0.0, 0.0, np.deg2rad(15))
maps = [(name, hexatwist.workspace_map(m, orientation, spacing=0.01)) for name, m in (("seed", seed),
                                                                                        ("designed", d.model))]
top = max(np.nanmax(np.rad2deg(m.max_twist)) for _, m in maps)
fig, axes = plt.subplots(1, 2, figsize=(12, 5.2), constrained_layout=True)
for ax, (name, m) in zip(axes, maps):
    extent = (m.u[0], m.u[-1], m.v[0], m.v[-1])
    im = ax.imshow(np.rad2deg(m.max_twist), origin="lower", extent=extent, cmap="viridis", vmin=0, vmax=top)
    ax.set(title=f"{name}: largest |twist| {np.nanmax(np.rad2deg(m.max_twist)):.1f} deg", xlabel="x [m]",
           ylabel="y [m]", aspect="equal")
fig.colorbar(im, ax=axes, label="largest |twist| over the legs [deg]")
fig.suptitle("x-y slice at z = 0, yaw 15 deg; blank: outside a limit")
path = os.path.join(out_dir, "python_08_design.png")
fig.savefig(path, dpi=100)
print(path)
