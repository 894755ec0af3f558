# SPDX-License-Identifier: BSD-3-Clause
"""Shared fixtures of the Python tests: the seed model, seeded random poses, the tools of the build."""
import os

import numpy as np
import pytest

import hexatwist


@pytest.fixture(scope="session")
def model():
    return hexatwist.default_model()


def random_poses(n, seed=7, translation=0.3, rotation=0.35):
    """n seeded random poses: x, y, z in +-translation [m], roll, pitch, yaw in +-rotation [rad]."""
    rng = np.random.default_rng(seed)
    scale = np.array([translation] * 3 + [rotation] * 3)
    return rng.uniform(-1.0, 1.0, (n, 6)) * scale


@pytest.fixture(scope="session")
def poses():
    return random_poses(10_000)


def tool(name):
    path = os.environ.get(name)
    if not path or not os.path.exists(path):
        pytest.skip(f"{name} not set (run through ctest)")
    return path
