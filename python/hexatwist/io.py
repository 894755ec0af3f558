# SPDX-License-Identifier: BSD-3-Clause
"""Files and formats (the library's io subsystem): models and configurations from YAML (the embedded
seed, text or a file), a configuration with its platform replaced, and the MuJoCo model. Reading a
bad file raises :class:`~hexatwist.ConfigError` with the library's one line "source:line:column:
field ..."; a missing file FileNotFoundError."""
from __future__ import annotations

import os
from typing import Union

from . import _hexatwist as _core
from ._hexatwist import Model
from .dynamics import RigLike

__all__ = ["default_model", "load_model", "seed_config_yaml", "corrected_config", "mjcf"]


def default_model() -> Model:
    """The embedded seed platform (configs/seed.yaml): Ra 1.2, Rb 1.5, da 0.2, db 0.3, H 1.511 m, lead 10 mm."""
    return _core.default_model()


def load_model(path_or_yaml: Union[str, os.PathLike[str]]) -> Model:
    """Model from a YAML file (a str without ':' or newline, or os.PathLike) or YAML text."""
    return _core.load_model(path_or_yaml)


def seed_config_yaml() -> str:
    """The embedded seed configuration (platform, servo, load, simulation, study) as YAML text."""
    return _core.seed_config_yaml()


def corrected_config(rig: RigLike, corrected: Model, header: str = "") -> str:
    """The configuration of ``rig`` (a Rig, YAML text, a path, or None for the seed) with its platform
    replaced by ``corrected`` (an identification's ``corrected_model``) in the legs form, the drives'
    reference recorded, every other key kept (platform_yaml.hpp): what ``hexatwist identify`` writes."""
    return _core._corrected_config(rig, corrected, header)


def mjcf(rig: RigLike = None) -> str:
    """The MJCF XML text (MuJoCo 2.2.2 or later) of a configuration: base, six legs of housing, rotor,
    screw, rod and rod end, the platform with its payload; actuators 'motor1' to 'motor6' whose force
    is the motor torque [N m] (positive lengthens the leg). SI units, frame B as the world. Raises
    ConfigError for what MuJoCo cannot represent (a leg with lead 0 or without U-joint axes, ...)."""
    return _core.mjcf(rig)
