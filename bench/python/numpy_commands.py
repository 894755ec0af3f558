# SPDX-License-Identifier: BSD-3-Clause
"""The compensated motor commands of hexatwist.commands written in plain numpy, for the benchmark.

The same computation as the library's motor_commands (docs/theory/kinematics.md §2-§6): inverse
kinematics (Eq. 1-4), the pose limits (stroke, U-joint bend seen from both ends, U-joint
singularity margin), the twist relative to home (§3), Eq. (12), the stroke test of the command, and
the platform-singularity limit from the 1-norm condition number of the motor-side Jacobian (§5-§6),
rotation columns divided by the condition length. Tuned as a numpy user would: vectorised over the
poses, vectors as separate (N, 6) arrays of x, y and z (numpy's cross and einsum cost several times
more), one batched 6x6 inverse. Only the accept/refuse decision and the commands are computed (the
library also names the leg and limit).
"""
import numpy as np


class NumpyModel:
    """The numbers of a hexatwist.Model the computation needs, as numpy arrays (one per axis)."""

    def __init__(self, model):
        base = np.asarray(model.base)
        pivot = np.asarray(model.pivot)
        arm = np.asarray(model.platform) - pivot
        ja = _unit(np.asarray(model.base_axes))
        jd = _unit(np.asarray(model.platform_axes))
        pivot_home = np.array([0.0, 0.0, model.home_height]) + pivot
        self.base, self.arm, self.ja, self.jd_P = base.T, arm.T, ja.T, jd.T  # (3, 6)
        self.pivot_home = pivot_home
        self.gain = np.asarray(model.twist_gain)
        self.offset = np.asarray(model.length_offsets)
        lim = model.limits
        self.length_min, self.length_max = lim["length_min"], lim["length_max"]
        self.cos_bend = np.cos(lim["bend_max"])
        self.cos2_margin = np.cos(lim["singularity_margin"]) ** 2
        self.condition_max = lim["jacobian_condition_max"]
        self.condition_length = np.linalg.norm(arm, axis=1).max()
        leg = pivot_home + arm - base
        s_home = leg / np.linalg.norm(leg, axis=1, keepdims=True)
        self.s_home = s_home.T
        x = np.sum(ja * jd, axis=1) - np.sum(ja * s_home, axis=1) * np.sum(jd * s_home, axis=1)
        y = np.sum(s_home * np.cross(ja, jd), axis=1)
        self.theta_home = np.arctan2(y, x)


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _rotate(R, v):
    """R (3, 3, N, 1) times the legs' v (3, 6) or (3, N, 6): (3, N, 6)."""
    return tuple(R[i][0] * v[0] + R[i][1] * v[1] + R[i][2] * v[2] for i in range(3))


def compensated_commands(m, poses):
    """(commands (N, 6) [m] with NaN rows where refused, accepted (N,) bool) for (N, 6) poses."""
    s_, c_ = np.sin(poses[:, 3:]), np.cos(poses[:, 3:])
    s4, s5, s6, c4, c5, c6 = (a[:, None] for a in (s_[:, 0], s_[:, 1], s_[:, 2], c_[:, 0], c_[:, 1], c_[:, 2]))
    # Eq. (3): R = Rz(yaw) Ry(pitch) Rx(roll); entries (N, 1).
    R = ((c5 * c6, s4 * s5 * c6 - c4 * s6, c4 * s5 * c6 + s4 * s6),
         (c5 * s6, s4 * s5 * s6 + c4 * c6, c4 * s5 * s6 - s4 * c6),
         (-s5, s4 * c5, c4 * c5))
    Rt = tuple(tuple(R[j][i] for j in range(3)) for i in range(3))
    arm = _rotate(R, m.arm)
    jd = _rotate(R, m.jd_P)
    L = tuple(m.pivot_home[k] + poses[:, k:k + 1] + arm[k] - m.base[k] for k in range(3))  # Eq. (1)-(4)
    length = np.sqrt(_dot(L, L))
    inv_length = 1.0 / length
    s = tuple(inv_length * L[k] for k in range(3))
    ja_s, jd_s = _dot(s, m.ja), _dot(s, jd)
    ok = (length >= m.length_min) & (length <= m.length_max)
    ok &= _dot(s, m.s_home) >= m.cos_bend
    ok &= _dot(_rotate(Rt, s), m.s_home) >= m.cos_bend  # the bend seen from the platform
    ok &= (ja_s * ja_s <= m.cos2_margin) & (jd_s * jd_s <= m.cos2_margin)
    # The twist relative to home (theory §3) and Eq. (12).
    ja_x_jd = _cross(m.ja, jd)
    x = _dot(m.ja, jd) - ja_s * jd_s
    y = _dot(s, ja_x_jd)
    dtheta = np.arctan2(y, x) - m.theta_home
    dtheta -= 2 * np.pi * np.round(dtheta / (2 * np.pi))
    command = length - m.offset - m.gain * dtheta
    ok &= (command >= m.length_min) & (command <= m.length_max)
    # The motor-side Jacobian's rows [s, arm x s] - gain * (twist Jacobian row) (theory §5), for the
    # poses that passed every leg test, rotation columns divided by the condition length.
    legs_ok = ok.all(axis=1)
    pick = lambda t: tuple(v[legs_ok] for v in t)
    s, arm, jd, ja_x_jd = pick(s), pick(arm), pick(jd), pick(ja_x_jd)
    x, y, ja_s, jd_s, inv_length = x[legs_ok], y[legs_ok], ja_s[legs_ok], jd_s[legs_ok], inv_length[legs_ok]
    n2 = x * x + y * y
    fx, fy = x / n2, y / n2
    g_s = tuple(fx * ja_x_jd[k] + fy * (jd_s * m.ja[k] + ja_s * jd[k]) for k in range(3))
    s_x_ja = _cross(s, m.ja)
    g_jd = tuple(fx * s_x_ja[k] - fy * (m.ja[k] - ja_s * s[k]) for k in range(3))
    g_s_s = _dot(g_s, s)
    a = tuple(inv_length * (g_s[k] - g_s_s * s[k]) for k in range(3))
    b = tuple(u + v for u, v in zip(_cross(arm, a), _cross(jd, g_jd)))
    arm_x_s = _cross(arm, s)
    J = np.empty((len(x), 6, 6))
    for k in range(3):
        J[:, :, k] = s[k] - m.gain * a[k]
        J[:, :, 3 + k] = (arm_x_s[k] - m.gain * b[k]) / m.condition_length
    inverse = np.linalg.inv(J)
    condition = np.abs(J).sum(axis=1).max(axis=1) * np.abs(inverse).sum(axis=1).max(axis=1)
    accepted = legs_ok.copy()
    accepted[legs_ok] = condition <= m.condition_max
    command[~accepted] = np.nan
    return command, accepted


def compensated_commands_chunked(m, poses, chunk=4096):
    """compensated_commands over blocks of `chunk` poses: every intermediate array stays in cache."""
    out = [compensated_commands(m, poses[i:i + chunk]) for i in range(0, len(poses), chunk)]
    return np.concatenate([c for c, _ in out]), np.concatenate([a for _, a in out])
