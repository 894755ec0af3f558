# SPDX-License-Identifier: BSD-3-Clause
"""Twist and length-error maps of a workspace slice (x-y plane 0.1 m above home, yaw 10 deg): 200 x 200
poses in one batch call per quantity; for leg 1 the twist [deg] and the length error it causes [mm], and
the largest |length error| over the six legs; poses outside a limit are blank. The twin of
examples/04_twist_map.cpp: the same numbers, the same lines printed.

    PYTHONPATH=build/python MPLBACKEND=Agg /usr/bin/python3 examples/python/04_twist_map.py [out_dir]
"""
import os
import sys

import matplotlib.pyplot as plt
import numpy as np

import hexatwist

out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
model = hexatwist.default_model()
xs = np.linspace(-0.5, 0.5, 200)
ys = np.linspace(-0.5, 0.5, 200)
X, Y = np.meshgrid(xs, ys)
poses = np.zeros((X.size, 6))
poses[:, 0], poses[:, 1], poses[:, 2], poses[:, 5] = X.ravel(), Y.ravel(), 0.1, np.deg2rad(10)

tw = hexatwist.twist(model, poses)
inside = hexatwist.commands(model, poses).ok  # the poses the platform may reach (every limit checked)
twist_in = np.where(inside[:, None], np.abs(tw.twist), 0.0)
error_in = np.where(inside[:, None], np.abs(tw.length_error), 0.0)
twist_at = np.unravel_index(np.argmax(twist_in), twist_in.shape)  # (pose, leg column) of the largest
error_at = np.unravel_index(np.argmax(error_in), error_in.shape)
print(f"{model.name}\nslice z = 0.1 m, yaw = 10 deg: {inside.sum()} of {inside.size} poses inside the limits")
print(f"largest |twist| {np.rad2deg(twist_in[twist_at]):.3f} deg (leg {twist_at[1] + 1}), largest |length error| "
      f"{1e3 * error_in[error_at]:.4f} mm (leg {error_at[1] + 1})")

twist_deg = np.where(inside[:, None], np.rad2deg(tw.twist), np.nan)
error_mm = np.where(inside[:, None], 1e3 * tw.length_error, np.nan)
fig, axes = plt.subplots(1, 3, figsize=(15, 4.6), constrained_layout=True)
extent = (xs[0], xs[-1], ys[0], ys[-1])
for ax, data, title, unit in [
    (axes[0], twist_deg[:, 0], "leg 1 twist", "deg"),
    (axes[1], error_mm[:, 0], "leg 1 length error (Eq. 10)", "mm"),
    (axes[2], np.where(inside, 1e3 * error_in.max(axis=1), np.nan), "largest |length error|, 6 legs", "mm"),
]:
    im = ax.imshow(data.reshape(X.shape), origin="lower", extent=extent, cmap="viridis")
    ax.set(title=title, xlabel="x [m]", ylabel="y [m]")
    fig.colorbar(im, ax=ax, label=unit)
fig.suptitle(f"{model.name}\nslice z = 0.1 m, yaw = 10 deg; blank: outside a limit ({100 * inside.mean():.0f}% inside)")
path = os.path.join(out_dir, "python_04_twist_map.png")
fig.savefig(path, dpi=80)
print(path)
