"""The rule that picks a structure among the candidates judged on held-out data."""

from __future__ import annotations

from dynid.identification.candidates import Candidate
from dynid.identification.selection import _chosen
from dynid.identification.structure import Structure


def _candidate(name: str, n_params: int, error: float, se: float = 0.01) -> Candidate:
    return Candidate(Structure.parse(name), n_params, error, error, se)


def test_of_as_many_parameters_the_structure_without_the_armature_is_kept():
    """An armature whose own rotors are all left out holds only rotors that regroup with
    the links: the same columns as the links alone, an error equal to round-off. It was
    kept when its round-off was lower, and the summary claimed an armature the arm has
    not."""
    lean = "links + viscous - fv3"
    same = "links + armature + viscous - fv3 - Ia3 - Ia4 - Ia5 - Ia6 - Ia7"
    judged = [
        _candidate("links", 40, 2.0),
        _candidate(lean, 46, 0.2874000001),
        _candidate(same, 46, 0.2874),
    ]
    assert _chosen(judged) == Structure.parse(lean)


def test_the_simplest_within_one_standard_error_is_kept():
    judged = [
        _candidate("links", 40, 1.0),
        _candidate("links + viscous", 47, 0.30, se=0.02),
        _candidate("links + viscous + coulomb", 54, 0.29, se=0.02),
    ]
    assert _chosen(judged) == Structure.parse("links + viscous")
