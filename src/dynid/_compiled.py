"""Optional compiled kernels: loading them, and laying arrays out for them.

The numba kernels (``dynamics/_kernels.py``, ``kinematics/_kernels.py``, ...) are optional:
without numba, or with the environment variable ``DYNID_NO_NUMBA`` set to anything but
``""`` or ``"0"``, the numpy reference paths run instead.
"""

from __future__ import annotations

import importlib
import os
from types import ModuleType

import numpy as np
from numpy.typing import NDArray

from . import _checks


def optional(module: str) -> ModuleType | None:
    """Import a kernel module, or None when numba is missing or ``DYNID_NO_NUMBA`` is set."""
    if os.environ.get("DYNID_NO_NUMBA", "") not in ("", "0"):
        return None
    try:
        return importlib.import_module(module)
    except ImportError:  # numba is not installed
        return None


def flat(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``x`` as a flat C-contiguous, aligned, writeable array (a view when it can be).

    The kernels then see a single argument type, so they are compiled once.
    """
    if x.ndim != 1:
        x = x.reshape(-1)
    return x if x.flags.carray else np.array(x)


def readonly(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``x`` as a read-only C array, as the robot's constants are (one kernel type)."""
    f = x.flags
    return x if f.c_contiguous and f.aligned and not f.writeable else _checks.frozen(x)
