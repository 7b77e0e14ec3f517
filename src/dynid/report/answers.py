"""Which answer a report opens with: one function per command (a registry), each reading
the run's files and returning an :class:`~dynid.report.run.Answer` or None.

A command with several answers (``identify --consistent``: the identification and the
consistent set) shows every verdict first, then every one's parts. A run that wrote the
files of an observer (events, thresholds, residuals) gets that answer whatever its
command. A command without an answer opens with its key numbers.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from . import demo, feasible, identify, observe, payload, torques
from .html import esc
from .run import Answer, RunFiles

__all__ = ["ANSWERS", "SIGN_WARNINGS", "answer_for"]

AnswerFunction = Callable[[RunFiles], Answer | None]

#: The answers of each command, in the order shown.
ANSWERS: dict[str, tuple[AnswerFunction, ...]] = {
    "identify": (identify.answer, feasible.answer),
    "validate": (torques.validate_answer,),
    "friction": (torques.friction_answer,),
    "retrieve": (feasible.answer,),
    "payload": (payload.payload_answer,),
    "demo": (demo.answer,),
}


#: Words of the warnings that say a recording's torque sign looks wrong (the opposite
#: sign to the model's, or a recorded sign map that looks wrong for the file).
SIGN_WARNINGS = ("anti-correlated", "opposite sign", "torque sign", "sign map")


def answer_for(run: RunFiles) -> Answer | None:
    """The page's answer: the command's answers merged (the first verdict, every part),
    with every warning of a torque sign the verdict does not already say at the top of
    its list (a sign warning changes what the verdict means)."""
    found = [a for f in (*ANSWERS.get(run.summary.command, ()), observe.answer) if (a := f(run))]
    if not found:
        return None
    more = tuple(a.verdict.replace('id="verdict"', "", 1) for a in found[1:])
    sections = more + tuple(s for a in found for s in a.sections)
    first = _with_sign_warnings(found[0].verdict, run.summary.warnings)
    return Answer(first, sections, frozenset().union(*(a.shown for a in found)))


def _with_sign_warnings(verdict: str, warnings: Sequence[str]) -> str:
    """``verdict`` (HTML) with each sign warning it does not hold first in its list."""
    said = [w for w in warnings if any(k in w for k in SIGN_WARNINGS) and esc(w) not in verdict]
    items = "".join(f'<li class="warning"><b>warning</b> {esc(w)}</li>' for w in said)
    return verdict.replace("<ul>", "<ul>" + items, 1) if items else verdict
