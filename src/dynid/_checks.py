"""Validation of user input at the public boundary.

Public functions convert array_like input once, here, to float64 and check shape and
finiteness; internal functions trust validated arrays.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .exceptions import NonFiniteError, ShapeError

#: arrays up to this size are checked element by element in Python (a numpy reduction
#: costs about 2 us whatever the size, the Python loop 40 ns an element)
_SMALL = 32


def finite(name: str, x: NDArray[np.float64]) -> None:
    """Raise :class:`NonFiniteError` naming ``name`` and the first bad index."""
    if x.size <= _SMALL and all(map(math.isfinite, x.ravel().tolist())):
        return
    if not np.isfinite(x).all():
        if x.ndim == 0:
            raise NonFiniteError(f"{name} must be finite; got {x.item()}")
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(x))[0])
        raise NonFiniteError(
            f"{name} must be finite; got {x[idx]} at index {idx if len(idx) > 1 else idx[0]}"
        )


def as_array(name: str, x: ArrayLike, *, allow_nonfinite: bool = False) -> NDArray[np.float64]:
    """Convert to a float64 array (a copy when needed) and check finiteness."""
    if x is None:  # numpy would read None as NaN
        raise ShapeError(f"{name} must be numeric array_like; got None")
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ShapeError(f"{name} must be numeric array_like; got {type(x).__name__}") from exc
    if not allow_nonfinite:
        finite(name, a)
    return a


def as_batch(name: str, x: ArrayLike, tail: tuple[int, ...], **kw: Any) -> NDArray[np.float64]:
    """Convert ``x`` and check that its trailing axes equal ``tail`` (leading axes are batch)."""
    a = as_array(name, x, **kw)
    k = len(tail)
    if a.ndim < k or a.shape[a.ndim - k :] != tail:
        want = ", ".join(["..."] + [str(t) for t in tail])
        raise ShapeError(f"{name} must have shape ({want}); got {a.shape}")
    return a


def as_exact(name: str, x: ArrayLike, shape: tuple[int, ...], **kw: Any) -> NDArray[np.float64]:
    """Convert ``x`` and check that its shape equals ``shape`` exactly."""
    a = as_array(name, x, **kw)
    if a.shape != shape:
        raise ShapeError(f"{name} must have shape {shape}; got {a.shape}")
    return a


def _read_only_throughout(a: Any) -> bool:
    """True for a read-only array whose memory nobody can write to: its chain of bases ends
    in a read-only buffer (the bytes of :func:`frozen`, a memory map opened read-only), not
    in an array that owns its data (whoever holds that one may make it writable again)."""
    while isinstance(a, np.ndarray):
        if a.flags.writeable or a.base is None:
            return False
        a = a.base
    try:
        return memoryview(a).readonly
    except TypeError:
        return False


def frozen(a: NDArray[Any]) -> NDArray[Any]:
    """``a`` as an array nobody can write to: ``a`` itself when it already is one (a large
    log is not copied again), else a copy kept in an immutable ``bytes`` buffer.

    A read-only copy that owned its data could be made writable again by anyone holding
    it (``setflags(write=True)``); over ``bytes`` numpy refuses. So a model built from the
    caller's arrays cannot change behind its back, and what is derived from it once (the
    compiled kernels' packed constants) stays valid.
    """
    if _read_only_throughout(a):
        return a
    if a.dtype.hasobject:  # no bytes for Python objects: a read-only copy
        b = np.array(a, copy=True)
        b.setflags(write=False)
        return b
    return np.frombuffer(a.tobytes(), dtype=a.dtype).reshape(a.shape)
