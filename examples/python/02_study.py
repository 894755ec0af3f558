"""The paper's Rz test (rotation about z, +-30 deg) re-plotted from hexatwist.study: the observation
error with conventional and compensated commands, and the twist of leg 1.

    PYTHONPATH=build/python MPLBACKEND=Agg /usr/bin/python3 examples/python/02_study.py [out_dir]
"""
import os
import sys

import matplotlib.pyplot as plt
import numpy as np

import hexatwist

out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
s = hexatwist.study(test="Rz")
summary = s.summary
assert summary["status"] == "ok", summary
conv, comp = s.conventional, s.compensated

fig, (a, b) = plt.subplots(2, 1, figsize=(9, 7), sharex=True, constrained_layout=True)
a.plot(conv.time, 1e3 * conv.error, label=f"conventional (max {1e3 * summary['conventional']['total']['max']:.3f} mm)")
a.plot(comp.time, 1e3 * comp.error, label=f"compensated (max {1e3 * summary['compensated']['total']['max']:.3f} mm)")
a.plot(conv.time, 1e3 * s.tracking_only, "--", lw=0.8, label="servo tracking only (no twist)")
a.set(ylabel="observation error [mm]", title="Rz test: rotation about z through +-30 deg")
a.legend()
b.plot(comp.time, np.rad2deg(comp.twist[:, 0]), label="leg 1 twist")
b.plot(comp.time, np.rad2deg(comp.desired[:, 5]), label="yaw commanded")
b.set(xlabel="time [s]", ylabel="[deg]")
b.legend()
path = os.path.join(out_dir, "python_02_study.png")
fig.savefig(path, dpi=80)
print(f"{path}: conventional max {1e3 * summary['conventional']['total']['max']:.4f} mm, "
      f"compensated max {1e3 * summary['compensated']['total']['max']:.4f} mm")
