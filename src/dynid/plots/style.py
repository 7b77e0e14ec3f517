"""The colour of each quantity the figures draw, one mapping for every figure.

A quantity keeps its colour from figure to figure of a report: the measured torques grey,
the identified model's prediction (with its friction) and its error blue, the rigid-body
model without friction orange, physically consistent parameters purple, in the torque
traces, the RMS bars and the error panels alike (the RMS bars drew "without friction" blue
beside a torque figure where blue was "with friction"). Legends stand outside the axes
or in an empty panel, where they cover no data.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

__all__ = ["COLOURS"]

#: Matplotlib colour of each quantity, by name.
COLOURS: Mapping[str, str] = MappingProxyType(
    {
        "measured": "0.35",  # measured torques
        "model": "tab:blue",  # the identified model's prediction with its friction, its error
        "no_friction": "tab:orange",  # the model without its friction, its error
        "consistent": "tab:purple",  # physically consistent link parameters (+ friction)
        "friction": "tab:red",  # a friction law fitted to the torque residual
        "samples": "0.55",  # scattered samples (the torque residual against velocity)
        "reference": "k",  # ground truth, published values, the prior, limits
        "residual": "tab:blue",  # the observer's residual: the model's external torques
        "external": "tab:green",  # the true external torques of a simulated contact
        "contact": "gold",  # a contact event's window
        "collision": "tab:red",  # a collision event's window
        "load": "tab:purple",  # a carried load's window (its pick: an external force)
        "label": "0.55",  # a labelled contact's window (hatched)
    }
)
