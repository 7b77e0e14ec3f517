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
    """True for a read-only array whose data belong to read-only numpy arrays only (a
    view of such an array cannot be made writable: nobody can change it)."""
    while isinstance(a, np.ndarray):
        if a.flags.writeable:
            return False
        if a.base is None:
            return True
        a = a.base
    return False


def frozen(a: NDArray[Any]) -> NDArray[Any]:
    """Return a read-only copy of ``a``, or ``a`` itself when it is read-only throughout
    (nobody can write into it, and a large log is not copied again)."""
    if _read_only_throughout(a):
        return a
    b = np.array(a, copy=True)
    b.setflags(write=False)
    return b
