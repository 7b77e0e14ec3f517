"""The compiled (numba) kernels of dynid, their numpy twins' registry and their dispatcher.

Every compiled kernel lives here, with the chain core they share; the public functions of
:mod:`dynid.kinematics`, :mod:`dynid.dynamics` and :mod:`dynid.regressors` call them
through one dispatcher and keep the numpy reference paths (the twins) beside their
documented API. The package is a base layer: it imports nothing above
:mod:`dynid._checks`, and a robot is anything with the model's arrays.

Modules:

* :mod:`~dynid._kernels.layout` (no numba): the packed constants ``C`` a kernel sees a
  robot as, and the array kinds of the kernels' arguments;
* :mod:`~dynid._kernels.dispatch` (no numba): :data:`~dynid._kernels.dispatch.KERNELS`,
  every kernel with its numpy twin; :func:`~dynid._kernels.dispatch.compiled`, the one
  decision "compiled or numpy"; :func:`~dynid._kernels.dispatch.run`, the common path of
  the public functions; :func:`~dynid._kernels.dispatch.single_sample`, their one
  single-sample fast path; :data:`~dynid._kernels.dispatch.CACHE`, the one cache (kernel
  modules, each robot's packed constants held outside the immutable robot, ...);
* :mod:`~dynid._kernels.chain`: the chain core (joint transform, chaining, motion, sine
  and cosine, compiler settings, stack scratch); :mod:`~dynid._kernels.dense`: Cholesky;
* the kernel modules, imported on first use: :mod:`~dynid._kernels.kinematics` (poses,
  Jacobians), :mod:`~dynid._kernels.dynamics` (RNEA, gravity, mass matrix, forward
  dynamics), :mod:`~dynid._kernels.regressors` (torque and static regressors),
  :mod:`~dynid._kernels.ik` (inverse kinematics), :mod:`~dynid._kernels.collision` (the
  distances of capsule segments, called by :func:`dynid.simulation.collision.self_distances`
  with its numpy path beside it, as :mod:`~dynid._kernels.filters` by the low-pass filter).

``import dynid._kernels`` does not import numba.
"""

from __future__ import annotations

from .dispatch import (
    CACHE,
    KERNELS,
    SMALL_CALLS,
    Kernel,
    Packed,
    cached,
    compiled,
    constants,
    constants_for,
    enabled,
    entry,
    find,
    frame_entry,
    load,
    loaded,
    packed,
    run,
    single_sample,
    small_call_uses_kernels,
)
from .layout import (
    C_AXIS,
    C_PHI,
    C_PRISMATIC,
    C_ROT,
    C_SLIDE,
    C_T,
    C_WIDTH,
    F64,
    SINGULAR_PIVOT,
    VECTOR,
    c_float64,
    flat,
    pack,
    pack_frame,
    readonly,
)

__all__ = [
    "CACHE",
    "KERNELS",
    "SMALL_CALLS",
    "Kernel",
    "Packed",
    "cached",
    "compiled",
    "constants",
    "constants_for",
    "enabled",
    "entry",
    "find",
    "frame_entry",
    "load",
    "loaded",
    "packed",
    "run",
    "single_sample",
    "small_call_uses_kernels",
    "C_AXIS",
    "C_PHI",
    "C_PRISMATIC",
    "C_ROT",
    "C_SLIDE",
    "C_T",
    "C_WIDTH",
    "F64",
    "SINGULAR_PIVOT",
    "VECTOR",
    "c_float64",
    "flat",
    "pack",
    "pack_frame",
    "readonly",
]
