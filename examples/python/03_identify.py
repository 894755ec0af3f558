"""Identification from the shipped tracker log (examples/tracker_Rz.csv: the Rz test after the
calibration moves, synthesised with leg offsets of up to 0.33 mm; truth in tracker_Rz.truth.json).

    PYTHONPATH=build/python MPLBACKEND=Agg /usr/bin/python3 examples/python/03_identify.py [out_dir]

A rotation about z cannot separate the observation point's height from the tracker's: on this log
identify (the basic model: the joints as configured) answers not_identifiable, naming the combination
(a status and a reason, not an exception).
A calibration run of random stations (every coordinate at once) determines everything: the same
offsets are then identified, with standard deviations, from simulated tracker points of 40 stations.
"""
import json
import os
import sys

import matplotlib.pyplot as plt
import numpy as np

import hexatwist

here = os.path.dirname(os.path.abspath(__file__))
out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
model = hexatwist.default_model()
log = hexatwist.read_point_log(os.path.join(here, "..", "tracker_Rz.csv"))
run = hexatwist.measured_test(test="Rz")
obs = hexatwist.observations_at_rest(model, run.t, run.poses, log.stamps, log.points)
r = hexatwist.identify(model, obs.motor, obs.points, calibration="basic")
print(f"tracker_Rz.csv: {len(log.stamps)} points, {len(obs.motor)} at rest at {obs.poses} poses")
print(f"identify: {r.status}: {r.reason or 'ok'}")
truth = np.asarray(json.load(open(os.path.join(here, "..", "tracker_Rz.truth.json")))["errors"]["zero_offset"])

# Stations: the real platform (the log's offsets) driven by the nominal compensated commands, seen
# by a tracker 30 deg about z and 2 m away, 1 um noise.
real = hexatwist.Model.from_arrays(model.base, model.platform, model.base_axes, model.platform_axes, model.home_height,
                                   lead=model.lead, length_offsets=truth, observation_point=model.observation_point,
                                   name="real", **{k: model.limits[k] for k in ("length_min", "length_max", "bend_max",
                                                                               "singularity_margin")})
rng = np.random.default_rng(2)
stations = rng.uniform(-1, 1, (120, 6)) * 0.2
c = hexatwist.commands(model, stations)
motor, stations = c.commands[c.ok][:40], stations[c.ok][:40]
fk = hexatwist.forward(real, motor, guess=stations)


def rotation(r, p, y):
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    return np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]) @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]) @ \
        np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])


a_B = np.array([[0, 0, model.home_height] + q[:3] + rotation(*q[3:]) @ model.observation_point for q in fk.poses])
R_BT, t_BT = rotation(0, 0, np.deg2rad(30)), np.array([2.0, -1.0, 0.5])
p_T = (a_B - t_BT) @ R_BT + rng.normal(0, 1e-6, a_B.shape)
# One point per station: the tracker's noise is given (it cannot be measured from a scatter at rest).
s = hexatwist.identify(model, motor, np.ascontiguousarray(p_T), calibration="basic", tracker_noise=1e-6)
print(f"identify on 40 stations: {s.status}; rms residual {1e3 * s.rms_before:.3f} mm -> {1e3 * s.rms_after:.4f} mm")
offsets = s.estimate[1:7]
for name, v, sd in zip(s.parameter_names, s.estimate, s.sd):
    if name == "lead" or name.startswith("offset"):
        print(f"  {name:>9}: {v * 1e3:+.4f} mm +- {sd * 1e3:.4f} mm")

fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5), constrained_layout=True)
a.plot(log.stamps, 1e3 * (log.points - log.points[0]), lw=0.8)
a.axvline(run.calibration_end, color="k", ls=":", label="calibration end")
a.set(xlabel="log time [s]", ylabel="tracker point - first point [mm]",
      title=f"tracker_Rz.csv (x, y, z): identify -> {r.status}")
a.legend()
legs = np.arange(1, 7)
b.bar(legs - 0.2, 1e3 * truth, 0.4, label="truth (tracker_Rz.truth.json)")
b.bar(legs + 0.2, 1e3 * offsets, 0.4, yerr=3e3 * s.sd[1:7], label="identified, 40 stations (+-3 sd)")
b.set(xlabel="leg", ylabel="length offset [mm]", title="leg length offsets")
b.legend(loc="lower right")
path = os.path.join(out_dir, "python_03_identify.png")
fig.savefig(path, dpi=80)
print(path)
