"""The identify report says what its held-out verdict's error is computed on: the
held-out recordings when whole recordings were left out (it said "the held-out block"),
the separate log, or the held-out time block.

Reference: heldout.json's ``block``, as the held-out judgement writes it for each scheme."""

from __future__ import annotations

import pytest

from dynid.report.identify import verdict_samples


@pytest.mark.parametrize(
    ("block", "said"),
    [
        (
            "each of the 2 recordings, predicted by the fit of the other 1",
            "the held-out recordings",
        ),
        (
            "the last of 3 recordings, predicted by the fit of the other 2",
            "the held-out recordings",
        ),
        ("the separate log (--validate-on)", "the separate log"),
        (
            "the last of 5 time blocks, 8.0-10.0 s, predicted by the fit of the other 4",
            "the held-out block",
        ),
    ],
)
def test_the_verdict_names_the_samples_of_its_held_out_scheme(block: str, said: str):
    """Each held-out scheme's block named as what the verdict's error is computed on."""
    assert verdict_samples({"block": block}) == f"every sample of {said}, torques as measured"
