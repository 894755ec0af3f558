# SPDX-License-Identifier: BSD-3-Clause
"""Identification from tracker logs (theory §13). examples/tracker_Rz.csv, the Rz test after the
calibration moves, cannot separate the observation point's height from the tracker's: identify answers
not_identifiable and names the combination (a status, not an exception). A run of 40 random stations,
every coordinate at once (examples/tracker_stations.csv, made by `hexatwist synth --stations 40
--station-seed 4 --offsets-mm 0.33 --seed 3 --rate 10`; the truth beside it), determines the legs' zero
offsets, which are compared with the truth. The twin of examples/06_identify.cpp: the same lines printed.

    PYTHONPATH=build/python MPLBACKEND=Agg /usr/bin/python3 examples/python/06_identify.py [out_dir]
"""
import json
import os
import sys

import matplotlib.pyplot as plt
import numpy as np

import hexatwist

here = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
out_dir = sys.argv[1] if len(sys.argv) > 1 else "."
rig = hexatwist.Rig()
model = rig.model


def identify_log(name: str, run: hexatwist.CommandedRun | hexatwist.StationsRun) -> tuple[hexatwist.PointLog,
                                                                                             hexatwist.Identification]:
    """The log's points at rest under a commanded run, identified with the basic model (the joints as
    configured: lead, zero offsets, observation point, tracker frame); prints what it found."""
    log = hexatwist.read_point_log(os.path.join(here, name))
    obs = hexatwist.observations_at_rest(model, run.t, run.poses, log.stamps, log.points, log.targets)
    print(f"{name}: {len(log.stamps)} points, {len(obs.motor)} at rest at {obs.stations} stations")
    r = hexatwist.identify(model, obs.motor, obs.points, obs.targets, calibration="basic")
    if r.status != "ok":
        print(f"identify: {r.status}: {r.reason}")
        return log, r
    print(f"identify: ok; rms residual {1e3 * r.rms_before:.4f} mm -> {1e3 * r.rms_after:.4f} mm, tracker noise "
          f"{1e3 * r.tracker_noise:.4f} mm")
    for name_k, v, sd in zip(r.parameter_names, r.estimate, r.sd):
        if name_k.startswith("offset"):
            print(f"  {name_k}: {1e3 * v:+.4f} mm +- {1e3 * sd:.4f} mm")
    return log, r


measured = hexatwist.measured_test(rig, "Rz")  # the calibration moves, then the study's Rz
rz_log, rz = identify_log("tracker_Rz.csv", measured)
stations_log, st = identify_log("tracker_stations.csv", hexatwist.stations_run(rig, count=40, seed=4))
with open(os.path.join(here, "tracker_stations.truth.json")) as f:
    truth = np.asarray(json.load(f)["errors"]["zero_offset"])
offsets = np.array([v for n, v in zip(st.parameter_names, st.estimate) if n.startswith("offset")])
sds = np.array([v for n, v in zip(st.parameter_names, st.sd) if n.startswith("offset")])
print("truth [mm]:", " ".join(f"{1e3 * v:+.4f}" for v in truth),
      f"(largest miss {np.abs(offsets - truth).max() / sds[np.argmax(np.abs(offsets - truth))]:.1f} sd)")

fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.5), constrained_layout=True)
for axis, name in enumerate("xyz"):
    a.plot(rz_log.stamps, 1e3 * (rz_log.points[:, axis] - rz_log.points[0, axis]), lw=0.8, label=f"{name} (tracker)")
a.axvline(measured.calibration_end, color="k", ls=":", label="calibration end")
a.set(xlabel="log time [s]", ylabel="tracker point - first point [mm]",
      title=f"tracker_Rz.csv (x, y, z): identify -> {rz.status}")
a.legend()
legs = np.arange(1, 7)
b.bar(legs - 0.2, 1e3 * truth, 0.4, label="truth (tracker_stations.truth.json)")
b.bar(legs + 0.2, 1e3 * offsets, 0.4, yerr=3e3 * sds, label="identified, 40 stations (+-3 sd)")
b.set(xlabel="leg", ylabel="zero offset [mm]", title="leg zero offsets")
b.legend(loc="lower right")
path = os.path.join(out_dir, "python_06_identify.png")
fig.savefig(path, dpi=80)
print(path)
