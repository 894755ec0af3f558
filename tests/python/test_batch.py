# SPDX-License-Identifier: BSD-3-Clause
"""Batch functions against the library called directly (bit for bit) and the CLI, FK round trips."""
import json
import subprocess

import numpy as np
import pytest

import hexatwist
from conftest import random_poses, tool


def reference(poses, tmp_path):
    """The C++ reference program (tests/python/reference.cpp) on the same poses."""
    src, dst = tmp_path / "poses.bin", tmp_path / "out.bin"
    np.ascontiguousarray(poses, dtype=np.float64).tofile(src)
    subprocess.run([tool("HEXATWIST_REFERENCE"), str(src), str(dst)], check=True, timeout=60)
    out = np.fromfile(dst).reshape(len(poses), 27)
    return dict(lengths=out[:, 0:6], twist=out[:, 6:12], compensated=out[:, 12:18], conventional=out[:, 18:24],
                twist_status=out[:, 24].astype(int), comp_status=out[:, 25].astype(int),
                conv_status=out[:, 26].astype(int))


def same_bits(a, b):
    """Equal bit for bit, NaN where NaN."""
    return np.array_equal(np.asarray(a).view(np.int64), np.asarray(b).view(np.int64)) or np.array_equal(a, b, equal_nan=True)


def test_commands_equal_the_library_bit_for_bit(model, poses, tmp_path):
    ref = reference(poses, tmp_path)
    comp = hexatwist.commands(model, poses, strategy="compensated")
    conv = hexatwist.commands(model, poses, strategy="conventional")
    assert np.array_equal(comp.status, ref["comp_status"])
    assert np.array_equal(conv.status, ref["conv_status"])
    assert np.array_equal(comp.commands, ref["compensated"], equal_nan=True)
    assert np.array_equal(conv.commands, ref["conventional"], equal_nan=True)
    assert comp.ok.sum() > 5000 and (~comp.ok).sum() > 100  # both outcomes exercised


def test_ik_and_twist_equal_the_library_bit_for_bit(model, poses, tmp_path):
    ref = reference(poses, tmp_path)
    ik = hexatwist.inverse_kinematics(model, poses)
    tw = hexatwist.twist(model, poses)
    assert np.array_equal(ik.lengths, ref["lengths"])
    assert np.array_equal(tw.status, ref["twist_status"])
    assert np.array_equal(tw.twist, ref["twist"], equal_nan=True)
    gain = model.twist_gain
    ok = tw.status == 0
    np.testing.assert_allclose(tw.length_error[ok], tw.twist[ok] * gain, rtol=1e-15, atol=0)
    np.testing.assert_allclose(np.linalg.norm(ik.axes, axis=2), 1.0, atol=1e-15)


def test_lengths_only_are_the_full_inverse_kinematics_lengths(model, poses):
    # The poses across the SIMD lanes (leg_lengths_batch): the same lengths and statuses, bit for bit.
    full = hexatwist.inverse_kinematics(model, poses)
    only = hexatwist.inverse_kinematics(model, poses, lengths_only=True)
    assert set(only) == {"lengths", "status"}
    assert np.array_equal(only.status, full.status)
    assert same_bits(only.lengths, full.lengths)
    one = hexatwist.inverse_kinematics(model, poses[3], lengths_only=True)
    assert one.lengths.shape == (6,) and np.array_equal(one.lengths, full.lengths[3])
    bad = poses[:5].copy()
    bad[2, 1] = np.nan
    with pytest.raises(hexatwist.InputError, match="row 2"):
        hexatwist.inverse_kinematics(model, bad, lengths_only=True)


def test_batch_equals_the_single_pose_path(model, poses):
    r = hexatwist.commands(model, poses)
    for i in range(len(poses)):
        if r.status[i] == 0:
            assert np.array_equal(hexatwist.motor_command(model, poses[i]), r.commands[i]), poses[i]
        else:
            with pytest.raises(hexatwist.StatusError) as e:
                hexatwist.motor_command(model, poses[i])
            assert e.value.status == hexatwist.STATUS_NAMES[r.status[i]]


def test_commands_of_legs_with_effects_are_the_single_pose_commands_and_ik(poses, tmp_path):
    """A configuration with leg_effects (stiff legs, play): the batch gives motor_command's commands of
    each pose (the static load's deflection at it, the play of the approach from home), as `ik` does,
    not the rigid legs' (they differed by up to 57 um before the batch took the effects)."""
    yaml = hexatwist.seed_config_yaml() + "\nleg_effects:\n  stiffness: 2.0e8\n  play: 50.0e-6\n"
    m = hexatwist.load_model(yaml)
    q = poses[:200]
    c = hexatwist.commands(m, q)
    ok = c.ok
    assert ok.sum() > 100
    single = np.array([hexatwist.motor_command(m, p) for p in q[ok]])
    assert np.array_equal(c.commands[ok], single)
    rigid = hexatwist.commands(hexatwist.default_model(), q)
    assert np.abs(c.commands[ok] - rigid.commands[ok]).max() > 1e-5
    path = tmp_path / "effects.yaml"
    path.write_text(yaml)
    pose = q[np.flatnonzero(ok)[0]]
    cli = json.loads(subprocess.run(
        [tool("HEXATWIST_CLI"), "ik", "--config", str(path), "--json",
         "--pose=" + ",".join(repr(v) for v in [*pose[:3], *np.degrees(pose[3:])])],
        capture_output=True, text=True, check=True).stdout)
    assert np.allclose([leg["command_compensated"] for leg in cli["legs"]], single[0], rtol=0, atol=1e-12)


def test_batch_equals_the_cli(model):
    cli = tool("HEXATWIST_CLI")
    rng = np.random.default_rng(3)
    for _ in range(12):
        # Short decimal text that the CLI and Python read to the same doubles; degrees as the CLI wants.
        xyz = np.round(rng.uniform(-0.3, 0.3, 3), 4)
        deg = np.round(rng.uniform(-15, 15, 3), 3)
        text = ",".join(repr(float(v)) for v in (*xyz, *deg))
        pose = np.array([*xyz, *(deg * (np.pi / 180.0))])
        out = subprocess.run([cli, "ik", "--json", f"--pose={text}"], capture_output=True, text=True, timeout=30)
        j = json.loads(out.stdout)
        legs = j["legs"]
        ik = hexatwist.inverse_kinematics(model, pose)
        tw = hexatwist.twist(model, pose)
        c = hexatwist.commands(model, pose)
        assert np.array_equal(ik.lengths, [l["length"] for l in legs]), text
        assert np.array_equal(tw.twist, [l["twist"] for l in legs]), text
        assert np.array_equal(tw.length_error, [l["length_error"] for l in legs]), text
        assert hexatwist.STATUS_NAMES[c.status] == j["status"]
        if j["status"] == "ok":
            assert np.array_equal(c.commands, [l["command_compensated"] for l in legs]), text


@pytest.mark.parametrize("kind", ["motor", "geometric"])
def test_fk_round_trip(model, poses, kind):
    c = hexatwist.commands(model, poses)
    q = poses[c.ok]
    lengths = c.commands[c.ok] if kind == "motor" else hexatwist.inverse_kinematics(model, q).lengths
    # From home for every pose, and warm-started along a smooth path.
    home = hexatwist.forward(model, lengths, kind=kind, guess=np.zeros(6))
    assert (home.status == 0).mean() > 0.99
    good = home.status == 0
    np.testing.assert_allclose(home.poses[good], q[good], atol=1e-9)
    assert home.residual[good].max() < 1e-11 and home.iterations[good].max() <= 30
    path = np.linspace(0, 1, 3000)[:, None] * np.array([0.2, -0.1, 0.25, 0.1, -0.15, 0.3])
    lp = hexatwist.commands(model, path).commands if kind == "motor" else hexatwist.inverse_kinematics(model, path).lengths
    chain = hexatwist.forward(model, lp, kind=kind)
    assert (chain.status == 0).all()
    np.testing.assert_allclose(chain.poses, path, atol=1e-9)
    each = hexatwist.forward(model, lp, kind=kind, guess=path)
    assert (each.iterations <= 2).all()


def test_fk_is_independent_of_chunking(model):
    path = np.linspace(0, 1, 3 * hexatwist.BLOCK + 17)[:, None] * np.array([0.2, -0.1, 0.25, 0.1, -0.15, 0.3])
    m = hexatwist.commands(model, path).commands
    whole = hexatwist.forward(model, m)
    parts = [hexatwist.forward(model, m[i:i + hexatwist.BLOCK]) for i in range(0, len(m), hexatwist.BLOCK)]
    for key in ("poses", "status", "iterations", "residual"):
        assert np.array_equal(whole[key], np.concatenate([p[key] for p in parts]), equal_nan=True)


def test_twist_of_heave_is_opposite_for_the_legs_of_a_pair(model):
    tw = hexatwist.twist(model, [0, 0, 0.2, 0, 0, 0]).twist
    assert tw[0] == pytest.approx(-tw[1], abs=1e-12) and abs(tw[0]) > 1e-3
