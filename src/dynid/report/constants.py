"""Which torque constants a log of motor currents checks, on the identify and validate
pages: the line the command printed after its verdict (``drive_gains.constants`` of
``heldout.json`` and ``validation.json``,
:meth:`~dynid.identification.drive_gains.DriveGains.constants_words`), one fact in the
verdict box; nothing for a log of torques or a file without it (an older one).
"""

from __future__ import annotations

from typing import Any

from .html import capitalised, esc

__all__ = ["constants_facts"]


def constants_facts(doc: Any) -> list[str]:
    """The fact of ``doc``'s ``drive_gains.constants`` (``doc``: heldout.json or
    validation.json as read), escaped: one item, or none."""
    gains = doc.get("drive_gains") if isinstance(doc, dict) else None
    said = gains.get("constants") if isinstance(gains, dict) else None
    return [esc(capitalised(said))] if isinstance(said, str) and said else []
