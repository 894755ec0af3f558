# SPDX-License-Identifier: BSD-3-Clause
"""hexatwist: twist-aware kinematics, dynamics, simulation, calibration and design of lead-screw
(U-P-U) Stewart platforms, from numpy.

One module per subsystem of the library, each re-exported here (``hexatwist.commands`` is
``hexatwist.kinematics.commands``): :mod:`hexatwist.core` (status codes, errors, threads, the
:class:`Result` base), :mod:`hexatwist.kinematics`, :mod:`hexatwist.motion`,
:mod:`hexatwist.dynamics`, :mod:`hexatwist.simulation`, :mod:`hexatwist.calibration`,
:mod:`hexatwist.design`, :mod:`hexatwist.io`, and :mod:`hexatwist.distributed` (Dask).

Conventions (details in :mod:`hexatwist.core`): a :class:`Model` first for kinematics, the workspace
and the identification, a :class:`Rig` first for dynamics, simulation, motor sizing and the study
(YAML text, a path or None are built for that call); every function returns a typed, frozen result
(``r.commands``, ``r.summary.status``; also readable as a mapping, ``r["commands"]``) that pickles;
legs are numbered 1 to 6 in every ``leg`` field and message (0: none), per-leg columns are numpy
indices 0 to 5; SI units. Poses are rows ``[x, y, z, roll, pitch, yaw]`` relative to home [m, rad],
R = Rz(yaw) Ry(pitch) Rx(roll) (paper Eq. 3). Batch functions take an (N, 6) float64 array (or one
(6,) pose), never copy a C-contiguous float64 input, release the GIL and spread the work over the
cores. Per-pose outcomes are int8 status codes (``STATUS_NAMES[code]``, 0 = ok); bad arguments raise
:class:`InputError` (a ValueError) with a one-line message, a bad configuration :class:`ConfigError`.
"""
from __future__ import annotations

from . import _hexatwist as _core
from . import calibration, core, design, distributed, dynamics, io, kinematics, motion, simulation
from .calibration import *  # noqa: F401,F403
from .core import *  # noqa: F401,F403
from .design import *  # noqa: F401,F403
from .distributed import *  # noqa: F401,F403
from .dynamics import *  # noqa: F401,F403
from .io import *  # noqa: F401,F403
from .kinematics import *  # noqa: F401,F403
from .motion import *  # noqa: F401,F403
from .simulation import *  # noqa: F401,F403

__all__: list[str] = []  # the subsystems' names (the modules themselves: hexatwist.kinematics, ...)
__all__ += core.__all__
__all__ += kinematics.__all__
__all__ += motion.__all__
__all__ += dynamics.__all__
__all__ += simulation.__all__
__all__ += calibration.__all__
__all__ += design.__all__
__all__ += io.__all__
__all__ += distributed.__all__

__version__: str = _core.version  # the library's version (hexatwist/version.hpp), as `hexatwist --version`


def _input_copies() -> int:
    """Debug counter: inputs the bindings had to copy (never a C-contiguous float64 array)."""
    return _core._input_copies()


core._follow_worker()
