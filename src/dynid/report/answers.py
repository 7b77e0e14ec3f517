"""Which answer a report opens with: one function per command (a registry), each reading
the run's files and returning an :class:`~dynid.report.run.Answer` or None.

A command with several answers (``identify --consistent``: the identification and the
consistent set) shows every verdict first, then every one's parts. A run that wrote the
files of an observer (events, thresholds, residuals) gets that answer whatever its
command. A command without an answer opens with its key numbers.
"""

from __future__ import annotations

from collections.abc import Callable

from . import demo, feasible, identify, observe, payload, torques
from .run import Answer, RunFiles

__all__ = ["ANSWERS", "answer_for"]

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


def answer_for(run: RunFiles) -> Answer | None:
    """The page's answer: the command's answers merged (the first verdict, every part)."""
    found = [a for f in (*ANSWERS.get(run.summary.command, ()), observe.answer) if (a := f(run))]
    if not found:
        return None
    more = tuple(a.verdict.replace('id="verdict"', "", 1) for a in found[1:])
    sections = more + tuple(s for a in found for s in a.sections)
    return Answer(found[0].verdict, sections, frozenset().union(*(a.shown for a in found)))
