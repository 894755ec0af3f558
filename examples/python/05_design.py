"""Designing the seed's U-joint axes from Python: the workspace's volume, the design, and the twist over
a slice before and after (the same arrays as `hexatwist workspace` and `hexatwist design`).

    PYTHONPATH=build/python MPLBACKEND=Agg /usr/bin/python3 examples/python/05_design.py [out_dir]

Prints the volume with its stated error and the largest twist before and after; draws the largest
|twist| over the x-y slice at z = 0 and yaw 15 deg for the seed and for the design, on one colour scale.
"""
import os
import sys

import matplotlib.pyplot as plt
import numpy as np

import hexatwist

out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
seed = hexatwist.default_model()
v = hexatwist.workspace_volume(seed)
print(f"workspace volume at home orientation: {v.volume:.4f} m^3 (stated error {v.error:.4f} m^3)")

d = hexatwist.design_axes(None)  # the study's tests and 2000 random combined poses, symmetric
print(f"largest |twist| over the required workspace: {np.rad2deg(d.before['max_twist']):.2f} deg -> "
      f"{np.rad2deg(d.after['max_twist']):.2f} deg; volume {d.before['volume']:.4f} -> {d.after['volume']:.4f} m^3")
print("turns of ja, jd [deg]:", np.round(np.rad2deg(d.turn_base), 2), np.round(np.rad2deg(d.turn_platform), 2))

orientation = (0.0, 0.0, np.deg2rad(15))
maps = [(name, hexatwist.workspace_map(m, orientation, spacing=0.01)) for name, m in (("seed", seed),
                                                                                        ("designed", d.model))]
top = max(np.nanmax(np.rad2deg(m.max_twist)) for _, m in maps)
fig, axes = plt.subplots(1, 2, figsize=(12, 5.2), constrained_layout=True)
for ax, (name, m) in zip(axes, maps):
    extent = [m.u[0], m.u[-1], m.v[0], m.v[-1]]
    im = ax.imshow(np.rad2deg(m.max_twist), origin="lower", extent=extent, cmap="viridis", vmin=0, vmax=top)
    ax.set(title=f"{name}: largest |twist| {np.nanmax(np.rad2deg(m.max_twist)):.1f} deg", xlabel="x [m]",
           ylabel="y [m]", aspect="equal")
fig.colorbar(im, ax=axes, label="largest |twist| over the legs [deg]")
fig.suptitle("x-y slice at z = 0, yaw 15 deg; blank: outside a limit")
path = os.path.join(out_dir, "05_design.png")
fig.savefig(path, dpi=100)
print("wrote", path)
