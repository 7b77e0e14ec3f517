"""Output folders: the set of files one command run writes into ``--out``, staged beside it
and moved into place complete (:mod:`dynid.outputs.run_output`).

The file formats themselves, and the atomic write every writer uses, are :mod:`dynid.io`.
"""

from __future__ import annotations

from .run_output import MANIFEST, RunOutput, run_output

__all__ = ["MANIFEST", "RunOutput", "run_output"]
