"""The identify report's rank line counts friction and offset columns apart, as the
summary does ("11 friction and 3 offset columns"; the report said "+ 14 friction").

Reference: the labels of the record's appended columns, counted by their kind."""

from __future__ import annotations

from dynid.report.identify import _rank_fact


def test_offsets_are_counted_apart_from_friction():
    """Motor friction fv, fc, an offset fo and a joint-side offset jfo: 2 friction and 2
    offset columns beside 3 base parameters, 7 columns in all."""
    doc = {
        "coefficients": [{"name": f"beta{k}"} for k in (1, 2, 3)],
        "rank": 7,
        "base": {"rank": 3},
        "metadata": {"friction_labels": ["fv1", "fc1", "fo1", "jfo2"]},
    }
    text, problems = _rank_fact(doc)
    assert "Rank <b>7 of 7</b>" in text and problems == []
    assert text.count("+ 2 friction + 2 offset") == 1, text
    doc["metadata"]["friction_labels"] = ["fv1", "fc1"]
    assert "+ 2 friction" in _rank_fact(doc)[0] and "offset" not in _rank_fact(doc)[0]


def test_rotor_inertias_of_their_own_are_counted_among_the_base_parameters():
    """A base whose independent columns hold two rotor inertias (``Ia3``, ``Ia4``: not
    regrouped with a link's) says so beside the count; a regrouped one (dependent) is not
    counted."""
    labels = ["m1", "J1zz", "Ia1", "Ia3", "Ia4"]
    doc = {
        "coefficients": [{"name": f"beta{k}"} for k in (1, 2, 3, 4)],
        "rank": 4,
        "base": {"rank": 4, "std_labels": labels, "independent": [0, 1, 3, 4]},
        "metadata": {},
    }
    text = _rank_fact(doc)[0]
    assert "4 base parameters (the structural rank of the kinematics; 2 of them rotor" in text
