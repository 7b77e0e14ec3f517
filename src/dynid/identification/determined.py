"""The words of the coefficients a structure selection kept because the data determine
them (``metadata.selection.kept_determined``), for the summary and the report alike; no
numerical import, so that the report's modules stay light (a one-shot ``dynid fk`` imports
neither scipy nor numba)."""

from __future__ import annotations

from typing import Any

__all__ = ["determined_sentence"]


def determined_sentence(kept: Any) -> str | None:
    """The sentence of the coefficients a selection kept because the data determine them
    (``metadata.selection.kept_determined``: ``coefficient``, ``std_percent``), or None:
    ``Ia5, Ia6 kept: determined to 2.9 %, 2.4 % (relative standard deviation), though
    held-out errors alone would leave them out``."""
    rows = [k for k in kept or () if isinstance(k, dict) and "coefficient" in k]
    if not rows:
        return None
    return (
        ", ".join(str(k["coefficient"]) for k in rows)
        + " kept: determined to "
        + ", ".join(f"{float(k.get('std_percent', float('nan'))):.2g} %" for k in rows)
        + " (relative standard deviation), though held-out errors alone would leave "
        + ("it" if len(rows) == 1 else "them")
        + " out"
    )
