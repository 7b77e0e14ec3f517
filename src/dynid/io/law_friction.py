"""A friction law's record, as ``feasible.json`` and the robot TOML hold it.

One record per friction: ``{"model": law, <param>: [one per joint], ...,
"standstill_band": [one per joint]}`` with the law's parameters by name (units of the law,
:mod:`dynid.friction.laws`: ``fv`` [N m s/rad], ``fc`` [N m], ``fo`` [N m], ...) and the
band [rad/s] of a law that has one: ``standstill_band``, the sign's dead zone of Coulomb
friction (the standstill band of the velocity noise), or for a smooth law ``width``, its
``tanh(dq / width)``'s width (a multiple of that band; read under ``standstill_band`` from
files of earlier versions); written only when not all zero, 0 when absent. Where it
acts (the joints, or the motors of the drive held beside it) is said by the file holding
the record, not by the record.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import _checks
from ..exceptions import DynidError
from ..friction.laws import LAWS
from ..friction.model import Friction
from ..model.drive import Drive
from .schema import fault

__all__ = ["law_friction", "law_record"]


def law_record(friction: Friction) -> dict[str, Any]:
    """``{"model": law, name: per-joint values, ..., "standstill_band": ...}`` of a friction
    (module docstring); the band only when the law has one and it is not all zero."""
    cols = {k: [float(x) for x in friction.params[:, j]] for j, k in enumerate(friction.names)}
    rec: dict[str, Any] = {"model": friction.kind} | cols
    if friction.law.standstill and np.any(friction.band > 0):
        rec[friction.law.band_key] = [float(x) for x in friction.band]
    return rec


def law_friction(
    rec: Mapping[str, Any], drive: Drive | None, n: int, source: str, key: str
) -> Friction:
    """The friction of a :func:`law_record` record, acting through ``drive`` (None: at the
    joints); ``source`` and ``key`` name the file and the record in errors.

    Raises
    ------
    DataError
        An unknown law, a parameter or band missing, not ``n`` numbers, or out of the law's
        bounds (the message names ``key.parameter``).
    """
    law = LAWS.get(str(rec.get("model")))
    if law is None:
        raise fault(source, f"{key}.model", f"expected one of {', '.join(LAWS)}")
    cols = []
    band = law.band_key if law.band_key in rec else "standstill_band"  # earlier files
    for name in (*law.params, band):
        v = rec.get(name, [0.0] * n if name == band else None)
        if not isinstance(v, list) or len(v) != n or not all(_finite(x) for x in v):
            want = f"{n} numbers (one per joint) for the {law.name} law's {name}"
            raise fault(source, f"{key}.{name}", f"expected {want}; got {_checks.short(v)}")
        cols.append(np.array(v, dtype=float))
    try:
        return law.model(np.column_stack(cols[:-1]), cols[-1], drive)
    except DynidError as exc:
        raise fault(source, key, str(exc)) from exc


def _finite(x: Any) -> bool:
    """A finite JSON/TOML number (never a boolean)."""
    if isinstance(x, bool) or not isinstance(x, int | float):
        return False
    try:
        return math.isfinite(float(x))
    except OverflowError:  # an integer beyond the float range
        return False
