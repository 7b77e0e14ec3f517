"""The one dispatcher of the compiled kernels, their registry and their one cache.

:data:`KERNELS` lists every compiled kernel once, with the module that holds it, its batch
and single-sample forms and its numpy twin (the reference path that computes the same to
rounding and raises the documented errors). :func:`compiled` is the single decision
"compiled or numpy": it returns the compiled form of a kernel for an input of ``ndim``
dimensions, or None, and the caller then takes the twin. It returns None when numba is
missing, when the environment variable ``DYNID_NO_NUMBA`` is set to anything but ``""``
or ``"0"`` (read when a kernel module is first asked for), and for a one-shot single
sample (:func:`small_call_uses_kernels`). A kernel itself declines (returns ``ok =
False``) a non-finite input and a chain too long for its stack scratch; the caller then
takes the twin or the batch form. :func:`run` is the common path of the public functions
over joint arrays: check the arrays cheaply, ask :func:`compiled`, call the kernel.

:func:`single_sample` is the one single-sample fast path: a decorator of the public
functions (``rnea``, ``mass_matrix``, ``gravity_torques``, ``coriolis``, ``forward_dynamics``,
``fk``, ``jacobian``) that sends float64 ``(n,)`` numpy arrays straight to the kernel's
compiled single-sample entry point once it is loaded, and everything else to the function
itself (which validates, and calls :func:`run` or its numpy twin). The wrapper takes the
function's own parameters, so a fast call costs no more Python frames than the function.

:data:`CACHE` holds everything the kernels memoise, outside the immutable robots: the
loaded kernel modules, the count of single-sample calls, each robot's packed constants
(:class:`Packed`, keyed by the robot's identity and dropped when the robot is garbage
collected, through a weak reference) and the inverse kinematics' option arrays. The
compiled forms of a kernel (batch function, single-sample entry point) are kept on its
:class:`Kernel` entry once loaded.

Importing this module does not import numba: the kernel modules are imported on first
use, by :func:`compiled`.
"""

from __future__ import annotations

import functools
import importlib
import os
import sys
import weakref
from collections.abc import Callable
from types import ModuleType
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from .layout import C_WIDTH, F64, VECTOR, c_float64, flat, pack, pack_frame, readonly

__all__ = [
    "Kernel",
    "KERNELS",
    "CACHE",
    "Packed",
    "compiled",
    "run",
    "load",
    "loaded",
    "enabled",
    "small_call_uses_kernels",
    "packed",
    "cached",
    "find",
    "constants",
    "constants_for",
    "entry",
    "frame_entry",
    "SMALL_CALLS",
    "single_sample",
]

#: single-sample calls that take the numpy path before the kernels are loaded for them
SMALL_CALLS = 256


class Kernel:
    """A compiled kernel registered with its numpy twin (one row of :data:`KERNELS`).

    ``module``: the kernel module of :mod:`dynid._kernels` (``"dynamics"``, ...);
    ``batch_name``, ``one_name``: its batch and single-sample functions (``one_name``
    None: a single sample takes the batch function); ``one_args``: the single-sample
    form's number of joint vectors and output dimensions, for its compiled entry point
    (:func:`entry`); ``twin``: the numpy reference, ``"module:function"``. ``batch`` and
    ``one`` hold the compiled forms once loaded (None before): the thin paths of the
    public functions read ``one``.
    """

    __slots__ = ("name", "module", "batch_name", "one_name", "one_args", "twin", "batch", "one")

    def __init__(
        self,
        name: str,
        module: str,
        batch: str | None,
        twin: str,
        one: str | None = None,
        one_args: tuple[int, int] | None = None,
    ) -> None:
        self.name, self.module, self.twin = name, module, twin
        self.batch_name, self.one_name, self.one_args = batch, one, one_args
        self.batch: Any = None
        self.one: Any = None


def _kernel_table(*rows: Kernel) -> dict[str, Kernel]:
    return {k.name: k for k in rows}


#: every compiled kernel and its numpy twin, by name
KERNELS: dict[str, Kernel] = _kernel_table(
    Kernel("link_poses", "kinematics", "link_poses", "dynid.kinematics.forward:link_poses_numpy"),
    Kernel(
        "frame_pose", "kinematics", "frame_pose", "dynid.kinematics.forward:fk_numpy",
        one="frame_pose", one_args=(1, 2),
    ),
    Kernel(
        "jacobian", "kinematics", "jacobian", "dynid.kinematics.jacobian:jacobian_numpy",
        one="jacobian_one", one_args=(1, 2),
    ),
    Kernel(
        "rnea", "dynamics", "rnea", "dynid.dynamics.rnea:rnea_numpy",
        one="rnea_one", one_args=(3, 1),
    ),
    Kernel(
        "gravity_torques", "dynamics", "gravity_torques",
        "dynid.dynamics.terms:gravity_torques_numpy",
        one="gravity_torques_one", one_args=(1, 1),
    ),
    Kernel(
        "mass_matrix", "dynamics", "mass_matrix", "dynid.dynamics.terms:mass_matrix_numpy",
        one="mass_matrix_one", one_args=(1, 2),
    ),
    Kernel(
        "forward_dynamics", "dynamics", None, "dynid.dynamics.terms:forward_dynamics_numpy",
        one="forward_dynamics_one", one_args=(3, 1),
    ),
    Kernel(
        "static_regressor", "regressors", "static_regressor",
        "dynid.regressors.static:static_regressor_numpy",
    ),
    Kernel(
        "torque_regressor", "regressors", "torque_regressor",
        "dynid.regressors.torque:torque_regressor_numpy",
    ),
    Kernel("ik", "ik", "solve_batch", "dynid.kinematics._ik_numpy:solve_numpy", one="solve_one"),
    Kernel(
        "momentum_terms", "observer", "momentum_terms",
        "dynid.observer.terms:momentum_terms_numpy",
    ),
)  # fmt: skip


class Packed:
    """A robot's arrays for the kernels, made once per robot and kept in :data:`CACHE`.

    ``C``: the constants (:func:`dynid._kernels.layout.pack`); ``C0``: the same without
    gravity (for the Coriolis and centrifugal torques); ``zeros``: a read-only ``(n,)``
    zero vector; ``vector``, ``matrix``, ``jacobian``: the shapes ``(n,)``, ``(n, n)`` and
    ``(6, n)`` of the single-sample paths; ``frames``: frame name -> ``(link, T_link_frame, CF)``
    (:func:`dynid._kernels.layout.pack_frame`), filled as frames are used, and ``flange``
    the flange's ``CF`` (the default frame, read without a lookup) once made; ``limits``:
    the inverse kinematics' limit arrays by ``(m, velocity_limits)``; ``ref``: the weak
    reference that drops this entry with the robot.
    Robots are immutable, so nothing here goes stale.
    """

    __slots__ = (
        "C", "C0", "zeros", "vector", "matrix", "jacobian", "frames", "flange", "limits", "ref",
    )  # fmt: skip

    def __init__(self, robot: Any) -> None:
        self.C = pack(robot)
        n = self.C.shape[0] - 1
        self.C0 = pack(robot, gravity=np.zeros(3))
        self.zeros = _checks.frozen(np.zeros(n))
        self.vector, self.matrix, self.jacobian = (n,), (n, n), (6, n)
        self.frames: dict[str, tuple[int, NDArray[np.float64], NDArray[np.float64]]] = {}
        self.flange: NDArray[np.float64] | None = None
        self.limits: dict[tuple[int, bool], tuple[NDArray, NDArray, NDArray]] = {}
        self.ref: Any = None


class Cache:
    """What the kernels memoise, in one place (:data:`CACHE`; see the module docstring).

    ``modules``: kernel module name -> module (None: numpy path); ``robots``: ``id(robot)``
    -> :class:`Packed` while the robot lives; ``robot``, ``last``: the robot whose packed
    arrays were asked for last, and those arrays (the single-sample paths check
    ``CACHE.robot is robot``, which costs no call; this one robot is held until another
    is used); ``small_calls``: single-sample calls so far (:func:`small_call_uses_kernels`);
    ``options``: ``id(options)`` -> the inverse-kinematics options (kept alive, so the id
    is theirs) and their ``(fpar, ipar)`` arrays.
    """

    __slots__ = ("modules", "robots", "robot", "last", "small_calls", "options")

    def __init__(self) -> None:
        self.modules: dict[str, ModuleType | None] = {}
        self.robots: dict[int, Packed] = {}
        self.robot: Any = None
        self.last: Packed | None = None
        self.small_calls = 0
        self.options: dict[int, tuple[Any, tuple[NDArray[np.float64], NDArray[np.int64]]]] = {}


#: the one cache of the kernels
CACHE = Cache()


def enabled() -> bool:
    """False when ``DYNID_NO_NUMBA`` asks for the numpy reference paths."""
    return os.environ.get("DYNID_NO_NUMBA", "") in ("", "0")


def load(module: str) -> ModuleType | None:
    """The kernel module ``dynid._kernels.<module>``, imported once, or None.

    None when numba is missing or ``DYNID_NO_NUMBA`` is set (read on the first call for
    each module).
    """
    mods = CACHE.modules
    try:
        return mods[module]
    except KeyError:
        pass
    mod = None
    if enabled():
        try:
            mod = importlib.import_module(f"{__package__}.{module}")
        except ImportError:  # numba is not installed
            mod = None
    mods[module] = mod
    return mod


def small_call_uses_kernels() -> bool:
    """Whether a single-sample call should load and use the compiled kernels.

    Importing numba and loading a kernel cost about a second, a single sample on the numpy
    path tens of microseconds to a millisecond: a one-shot call (a command line call on one
    configuration) stays on the numpy path. Once numba is imported (by any batch call) or
    after :data:`SMALL_CALLS` single-sample calls in the process, the kernels are used
    (rent or buy). Both paths give the same numbers to rounding (about 1e-15 relative).
    """
    if "numba" in sys.modules:
        return True
    CACHE.small_calls += 1
    return CACHE.small_calls > SMALL_CALLS


def compiled(kernel: Kernel, ndim: int) -> Any:
    """The compiled form of ``kernel`` for an input of ``ndim`` dimensions, or None.

    The single dispatcher: a batch (``ndim > 1``) loads the kernel module, a single sample
    (``ndim == 1``) uses it once loaded, else as :func:`small_call_uses_kernels` decides.
    A single sample gets the single-sample entry point (:func:`entry`) when the kernel has
    one, else the batch function. None: take the numpy twin.
    """
    if ndim == 1:
        e = kernel.one
        if e is not None:
            return e
    elif kernel.batch is not None:
        return kernel.batch
    if kernel.module not in CACHE.modules and ndim <= 1 and not small_call_uses_kernels():
        return None
    mod = load(kernel.module)
    if mod is None:
        return None
    if kernel.batch is None and kernel.batch_name is not None:
        kernel.batch = getattr(mod, kernel.batch_name)
    if ndim > 1:
        return kernel.batch
    if kernel.one_name is None:  # a single sample takes the batch function
        kernel.one = kernel.batch
        return kernel.one
    if kernel.one_args is None:
        kernel.one = getattr(mod, kernel.one_name)
    else:
        vectors, out_ndim = kernel.one_args
        C = _checks.frozen(np.zeros((3, C_WIDTH)))
        out = np.zeros((1,) * out_ndim)
        kernel.one = entry(getattr(mod, kernel.one_name), C, *(VECTOR,) * vectors, out)
    return kernel.one


def loaded(kernel: Kernel) -> Any:
    """:func:`compiled` for a single sample when ``kernel``'s module is loaded already, else
    None (nothing is loaded and no call is counted)."""
    if kernel.one is not None:
        return kernel.one
    if CACHE.modules.get(kernel.module) is None:
        return None
    return compiled(kernel, 1)


def run(
    kernel: Kernel,
    robot: Any,
    arrays: tuple[Any, ...],
    tail: tuple[int, ...],
    C: NDArray[np.float64] | None = None,
) -> NDArray[np.float64] | None:
    """``kernel`` on joint arrays of one shape ``(..., n)``: the result, ``(...) + tail``.

    ``arrays`` pass when they are float64 arrays of at least one dimension (C-contiguous
    ones without a copy) of one shape ending in ``n``; the kernel gets ``C`` (default:
    the robot's :func:`constants`), the arrays flat and an output array. None (the caller
    takes the numpy twin, which validates and raises the documented errors) when an array
    does not pass, :func:`compiled` says numpy, or the kernel declines (``ok = False``:
    a non-finite input, or a chain too long for a single-sample kernel's stack scratch).
    """
    a = c_float64(arrays[0])
    if a is None:
        return None
    shape = a.shape
    if shape[-1] != len(robot.joint_names):
        return None
    flats = [flat(a)]
    for x in arrays[1:]:
        a = c_float64(x)
        if a is None or a.shape != shape:
            return None
        flats.append(flat(a))
    ndim = len(shape)
    f = compiled(kernel, ndim)
    if f is None:
        return None
    if C is None:
        c = CACHE
        C = c.last.C if c.robot is robot and c.last is not None else packed(robot).C
    out = np.empty(shape[:-1] + tail)  # (tail: the result of one sample, e.g. (n,))
    # one sample through a single-sample entry point: the output as it is (the entry points
    # are typed for it); a batch, or one sample on the batch function (``link_poses``):
    # flat, so that a batch kernel is compiled once whatever the shape
    if f(C, *flats, out if ndim == 1 and kernel.one_name else out.reshape(-1)):
        return out
    return None


def packed(robot: Any) -> Packed:
    """``robot``'s :class:`Packed` arrays, made on the first call and kept in :data:`CACHE`.

    Keyed by ``id(robot)``; a weak reference to the robot removes the entry when the robot
    is collected (before its id can be reused).
    """
    robots = CACHE.robots
    key = id(robot)
    p = robots.get(key)
    if p is None:
        p = Packed(robot)
        p.ref = weakref.ref(robot, _dropper(key))
        robots[key] = p
    CACHE.robot, CACHE.last = robot, p
    return p


def find(robot: Any) -> Packed | None:
    """``robot``'s :class:`Packed` arrays if made (then also :attr:`Cache.last`), else None.

    The single-sample paths read ``CACHE.last`` when ``CACHE.robot is robot`` and call
    this otherwise.
    """
    p = CACHE.robots.get(id(robot))
    if p is not None:
        CACHE.robot, CACHE.last = robot, p
    return p


def _dropper(key: int) -> Any:
    """The weak-reference callback that drops the robot ``key``'s entry of the cache."""
    robots = CACHE.robots

    def drop(_: Any) -> None:
        robots.pop(key, None)

    return drop


def cached(robot: Any) -> Packed | None:
    """``robot``'s :class:`Packed` arrays if made, else None (nothing is made)."""
    return CACHE.robots.get(id(robot))


def constants(robot: Any) -> NDArray[np.float64]:
    """:func:`dynid._kernels.layout.pack` of ``robot``, computed once per robot."""
    return packed(robot).C


def constants_for(robot: Any, phi: Any, gravity: Any) -> NDArray[np.float64]:
    """The constants of ``robot`` with parameters ``phi`` (n, 10) and ``gravity`` (3,).

    The robot's own packed arrays when these are the robot's (``C``) or the robot's with
    gravity off (``C0``); otherwise packed anew (validated arrays).
    """
    if phi is robot.phi:
        if gravity is robot.gravity:
            return constants(robot)
        if gravity.tolist() == [0.0, 0.0, 0.0]:
            return packed(robot).C0
    return pack(robot, np.asarray(phi, dtype=np.float64), gravity)


def frame_entry(robot: Any, frame: str) -> tuple[int, NDArray, NDArray]:
    """``(link, T_link_frame, CF)`` of ``frame`` (:attr:`Packed.frames`), made on first use.

    ``CF`` are the kernels' constants with the frame (:func:`dynid._kernels.layout.
    pack_frame`). Raises :class:`dynid.exceptions.UnknownNameError` for anything but a
    frame's name (through ``robot.frame``).
    """
    p = packed(robot)
    hit = p.frames.get(frame) if isinstance(frame, str) else None
    if hit is None:
        f = robot.frame(frame)
        T = readonly(f.T_link_frame)
        hit = p.frames[frame] = (f.link, T, pack_frame(p.C, f.link, T))
        if frame == "flange":
            p.flange = hit[2]
    return hit


def entry(kernel: Any, *args: Any) -> Any:
    """The compiled entry point of ``kernel`` for the numba types of ``args``.

    Calling it skips numba's per-call type dispatch (a few hundred ns for five array
    arguments), which dominates a single-sample call. The caller must then pass arguments
    of exactly these kinds, because the entry point reads an array as the type it was
    compiled for without checking its item type or number of dimensions: the thin paths
    check that the class is ``np.ndarray``, the dtype float64 and the shape ``(n,)``; the
    joint vectors are typed with any strides (:data:`dynid._kernels.layout.VECTOR`), the
    outputs are new C arrays. Returns ``kernel`` when numba offers no entry point.
    """
    try:
        from numba import typeof

        sig = tuple(typeof(a) for a in args)
        kernel.compile(sig)
        return kernel.overloads[sig].entry_point
    except Exception:  # noqa: BLE001 (an internal of numba moved: use the dispatcher)
        return kernel


# ----------------------------------------------------------------- the single-sample path
_ND, _F64 = np.ndarray, F64
#: a single-sample result's shape: ``(n,)``, ``(n, n)``, ``(6, n)``, ``(4, 4)``
OUTPUTS = ("vector", "matrix", "jacobian", "pose")
_F = TypeVar("_F", bound=Callable[..., Any])


def single_sample(kernel: Kernel, form: str, output: str) -> Callable[[_F], _F]:
    """The single-sample fast path of a public function, as a decorator (the only one).

    ``kernel``: the :data:`KERNELS` row whose single-sample entry point (:attr:`Kernel.one`,
    set once the kernel module is loaded) computes the function; ``output``: the result's
    shape, one of :data:`OUTPUTS`; ``form``: the function's parameters and the constants
    the entry point takes:

    * ``"configuration"``: ``f(robot, q)``, constants ``C`` (``mass_matrix``,
      ``gravity_torques``);
    * ``"states"``: ``f(robot, q, dq, ddq, *, gravity=None)``, ``C``, fast only without
      ``gravity`` (``rnea``);
    * ``"torques"``: ``f(robot, q, dq, tau)``, ``C`` (``forward_dynamics``);
    * ``"velocities"``: ``f(robot, q, dq)``, ``C0`` (no gravity) and a zero acceleration
      (``coriolis``, on the RNEA kernel);
    * ``"frame"``: ``f(robot, q, frame="flange", tool=None)``, the frame's constants ``CF``
      once made (:func:`frame_entry`), fast only without ``tool`` (``fk``, ``jacobian``).

    A call whose arrays are exactly float64 numpy ``(n,)`` vectors of a robot whose packed
    arrays exist (:func:`find`) goes to the entry point, which checks finiteness; anything
    else, a declined input and an object that fakes its class (the entry point raises
    TypeError) go to the decorated function. The wrapper has the function's name, docstring
    and signature (:func:`functools.wraps`).
    """
    make = _FORMS[form]
    if output not in OUTPUTS:
        raise ValueError(f"output must be one of {OUTPUTS}; got {output!r}")

    def decorate(general: _F) -> _F:
        return functools.wraps(general)(make(kernel, general, output))  # type: ignore[return-value]

    return decorate


def _configuration(kernel: Kernel, general: Any, output: str) -> Any:
    matrix = output == "matrix"  # else a vector

    def one(robot: Any, q: Any) -> Any:
        e = kernel.one
        if e is not None and q.__class__ is _ND and q.dtype is _F64:
            p = CACHE.last if CACHE.robot is robot else find(robot)
            if p is not None and q.shape == p.vector:
                out = np.empty(p.matrix if matrix else p.vector)
                try:  # (an object can fake its class; the entry point then refuses it)
                    if e(p.C, q, out):
                        return out
                except TypeError:
                    pass
        return general(robot, q)

    return one


def _states(kernel: Kernel, general: Any, output: str) -> Any:
    def one(robot: Any, q: Any, dq: Any, ddq: Any, *, gravity: Any = None) -> Any:
        e = kernel.one
        if (
            e is not None
            and gravity is None
            and q.__class__ is dq.__class__ is ddq.__class__ is _ND
            and q.dtype is dq.dtype is ddq.dtype is _F64
        ):
            p = CACHE.last if CACHE.robot is robot else find(robot)
            if p is not None and q.shape == dq.shape == ddq.shape == p.vector:
                out = np.empty(p.vector)  # (their result is a vector)
                try:
                    if e(p.C, q, dq, ddq, out):
                        return out
                except TypeError:
                    pass
        return general(robot, q, dq, ddq, gravity=gravity)

    return one


def _torques(kernel: Kernel, general: Any, output: str) -> Any:
    def one(robot: Any, q: Any, dq: Any, tau: Any) -> Any:
        e = kernel.one
        if (
            e is not None
            and q.__class__ is dq.__class__ is tau.__class__ is _ND
            and q.dtype is dq.dtype is tau.dtype is _F64
        ):
            p = CACHE.last if CACHE.robot is robot else find(robot)
            if p is not None and q.shape == dq.shape == tau.shape == p.vector:
                out = np.empty(p.vector)  # (their result is a vector)
                try:
                    if e(p.C, q, dq, tau, out):
                        return out
                except TypeError:
                    pass
        return general(robot, q, dq, tau)

    return one


def _velocities(kernel: Kernel, general: Any, output: str) -> Any:
    def one(robot: Any, q: Any, dq: Any) -> Any:
        e = kernel.one
        if e is not None and q.__class__ is dq.__class__ is _ND and q.dtype is dq.dtype is _F64:
            p = CACHE.last if CACHE.robot is robot else find(robot)
            if p is not None and q.shape == dq.shape == p.vector:
                out = np.empty(p.vector)  # (their result is a vector)
                try:
                    if e(p.C0, q, dq, p.zeros, out):
                        return out
                except TypeError:
                    pass
        return general(robot, q, dq)

    return one


def _frame(kernel: Kernel, general: Any, output: str) -> Any:
    pose = output == "pose"  # else a Jacobian

    def one(robot: Any, q: Any, frame: str = "flange", tool: Any = None) -> Any:
        e = kernel.one
        if e is not None and q.__class__ is _ND and tool is None and q.dtype is _F64:
            p = CACHE.last if CACHE.robot is robot else find(robot)
            if p is not None and q.shape == p.vector:
                try:  # (unhashable frames, and objects that fake their class, go the general way)
                    CF = p.flange if frame == "flange" else p.frames.get(frame, (None,) * 3)[2]
                    if CF is not None:
                        out = np.empty((4, 4) if pose else p.jacobian)
                        if e(CF, q, out):
                            return out
                except TypeError:
                    pass
        return general(robot, q, frame, tool)

    return one


_FORMS = {
    "configuration": _configuration,
    "states": _states,
    "torques": _torques,
    "velocities": _velocities,
    "frame": _frame,
}
