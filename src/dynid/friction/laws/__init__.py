"""The registry of friction laws: one module per law, one line each here.

===================  ==========================================================  ===============
name                 law                                                         fit
===================  ==========================================================  ===============
``none``             ``0`` (no extra friction)                                   none
``classical``        ``fv dq + fc s(dq) + fo`` (Gaz et al. 2019, eq. 24)         bounded linear
``smooth``           ``fv dq + fc tanh(dq / w) + fo``, ``w`` the sign's width    bounded linear
``quadratic``        ``fv dq + fq dq |dq| + fc s(dq) + fo``                      bounded linear
``asymmetric``       ``fv+ dq+ + fv- dq- + fc+ [s > 0] - fc- [s < 0]``           bounded linear
``stribeck``         ``fv dq + (fc + (fs - fc) exp(-(dq/vst)^2)) s(dq) + fo``    var. projection
``smooth_stribeck``  the same with ``tanh(dq / w)`` for ``s(dq)``                var. projection
``sigmoid``          Gaz et al. 2019, eq. 25                                     Nelder-Mead
===================  ==========================================================  ===============

``s(dq)`` is the sign outside the standstill band (:mod:`dynid.friction.laws.base`); ``w``
the smooth sign's width, a multiple of that band (``width`` in files). The
registry gives ``--friction-model``'s choices, ``friction.json``'s ``model`` values, the
candidates of the selection (:mod:`dynid.friction.select`) and the MuJoCo mapping. Adding
a law: a module here defining ``LAW`` (a :class:`~dynid.friction.laws.base.FrictionLaw`,
:func:`~dynid.friction.laws.base.linear_law` for a law linear in its parameters), its line
in :data:`LAWS`, and its test.
"""

from __future__ import annotations

from ...exceptions import OptionError
from . import asymmetric, classical, none, quadratic, sigmoid, smooth, smooth_stribeck, stribeck
from .base import FrictionLaw

__all__ = ["LAWS", "FrictionLaw", "law_named"]

#: The laws by name, simplest first (the selection prefers the earlier on a tie).
LAWS: dict[str, FrictionLaw] = {
    law.name: law
    for law in (
        none.LAW,
        classical.LAW,
        smooth.LAW,
        quadratic.LAW,
        asymmetric.LAW,
        stribeck.LAW,
        smooth_stribeck.LAW,
        sigmoid.LAW,
    )
}


def law_named(name: str) -> FrictionLaw:
    """The law called ``name``.

    Raises
    ------
    OptionError
        No law has that name (the message lists them, as ``--friction-model`` takes them).
    """
    law = LAWS.get(name)
    if law is None:
        raise OptionError(f"--friction-model must be one of {', '.join(LAWS)}; got {name!r}")
    return law
