"""The torque signs a ``--units`` text reads a file with, and the ``--units`` text that
reads it with others: a hint for a file whose torques the applied sign map reads the wrong
way (``tau=-1`` applied to a file already in dynid's sign: ``tau=1``); of several files,
the one text that reads each right (:func:`units_reading`: ``tau=-1,b.csv:tau=-1`` where
b.csv alone is already in dynid's sign). ``validate``, ``identify``, ``friction``,
``payload`` and ``observe`` hint it (``dynid.workflows.recordings.check_sign_map``).

A file's torques on joint ``k`` are read negated when the ``tau`` factor is negative
(``tau=-1``) or when a single joint's entry flips it (``tau3=-1``, or the file's own
``rec2.csv:tau3=-1``), not both (:class:`~dynid.io.columns.ColumnMap`: the flips act
after the factor). Joints are counted from 0 in the code, from 1 in the entries.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

from .columns import ColumnMap, parse_column_map

__all__ = ["tau_negated", "units_negating", "units_reading"]


def tau_negated(cmap: ColumnMap, n: int) -> tuple[int, ...]:
    """The joints (from 0, of ``n`` torque columns) whose torques ``cmap`` reads negated:
    every joint with a negative ``tau`` factor, the flipped joints' (``tau3=-1``) the other
    way. ``cmap`` is the map a file is read with (:meth:`ColumnMap.for_file`)."""
    whole = cmap.factor("tau") < 0.0
    flips = set(cmap.flips.get("tau", ()))
    return tuple(k for k in range(n) if whole != (k in flips))


def units_negating(units: str, joints: Iterable[int], n: int) -> str:
    """The ``--units`` text that reads a file as ``units`` does, with exactly the torques
    of ``joints`` (from 0, of ``n``) negated: every entry of ``units`` that is no torque
    sign kept (``q=deg``, the torques' unit: ``tau=-0.001`` as ``tau=0.001``), the torque
    signs (``tau=-1``'s sign, ``tau3=-1``, a file's own ``rec2.csv:tau=-1``) replaced by
    the fewest entries: one per joint of ``joints`` (``tau2=-1``), or, when they are more
    than half the joints and the torques' unit is a number, the factor negated and one
    entry per joint not negated (``tau=-1,tau3=-1``); ``tau=Nm`` when nothing is left.

    ``units_negating("q=deg,tau=-1", [], 6)`` is ``"q=deg,tau=1"``; ``units_negating(
    "tau3=-1", [], 6)`` is ``"tau=Nm"``.
    """
    negated = sorted(set(joints))
    kept, unit = [], "1"
    for entry in units.split(","):
        key, _, value = entry.partition("=")
        key, value = key.strip(), value.strip()
        if not key or ":" in key or (key.startswith("tau") and key[3:].isdigit()):
            continue  # a file's own entry, or a joint's torque sign
        if key == "tau":
            unit = value.removeprefix("-").strip()  # its sign left to the entries below
            continue
        kept.append(f"{key}={value}")
    numeric = unit[:1].isdigit() or unit[:1] == "."
    if numeric and 2 * len(negated) > n:
        kept.append(f"tau=-{unit}")
        kept += [f"tau{k + 1}=-1" for k in range(n) if k not in negated]
    else:
        kept += ([f"tau={unit}"] if unit != "1" or "tau=" in units else []) + [
            f"tau{k + 1}=-1" for k in negated
        ]
    return ",".join(kept) or "tau=Nm"


def units_reading(units: str, wanted: Mapping[str, Iterable[int]], n: int) -> str | None:
    """The ``--units`` text that reads each file of ``wanted`` (by name) with exactly the
    torques of its joints (from 0, of ``n``) negated, as ``units`` reads it otherwise:
    the set most files want (the first file's on a tie) written as
    :func:`units_negating` writes it, each other file's own entries beside it, the fewest
    (``b.csv:tau=-1``, ``b.csv:tau3=-1``). None where a file's own entries cannot read it
    so: a joint every file flips (``tau3=-1``) stays flipped in each, a file's own flips
    adding to it.

    ``units_reading("tau=-1", {"a.csv": range(6), "b.csv": []}, 6)`` is
    ``"tau=-1,b.csv:tau=-1"``; with ``"b.csv": range(6)`` too, ``"tau=-1"``.
    """
    sets = {name: frozenset(ks) for name, ks in wanted.items()}
    common = max(sets.values(), key=list(sets.values()).count)
    text = units_negating(units, common, n)
    cmap = parse_column_map(None, text)
    whole, flips = cmap.factor("tau") < 0.0, set(cmap.flips.get("tau", ()))
    out = [text]
    for name, want in sets.items():
        if want == common:
            continue
        options: list[list[str]] = []
        for own_sign in (False, True):  # the file's own tau=-1 negates its factor
            sign = whole != own_sign
            need = {k for k in range(n) if sign != (k in want)}  # joints to flip
            if flips <= need:
                options.append(
                    ([f"{name}:tau=-1"] if own_sign else [])
                    + [f"{name}:tau{k + 1}=-1" for k in sorted(need - flips)]
                )
        if not options:
            return None
        out += sorted(options, key=len)[0]
    return ",".join(out)
