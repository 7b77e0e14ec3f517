"""Findings of ``identify`` recorded in ``identification.json`` that the verdict of its page
says, each as a titled fact with its numbers.

* ``metadata.confounded_offsets``: a torque offset the structure left out that the
  training's poses cannot tell from another coefficient (that coefficient carries it, right
  at those poses only; :mod:`~dynid.identification.confounded_offset`);
* ``metadata.selection.spring_candidate``: the search run again with a joint spring the
  held-out residual named, and whether its choice was kept
  (:mod:`~dynid.identification.spring_candidate`);
* ``metadata.recording_offsets``: torque offsets that differ between recordings, fitted
  one per recording and joint (:mod:`~dynid.identification.recording_offsets`), with a
  titled table of every offset;
* ``metadata.selection.differing_recordings``: a recording, not outlying, whose held-out
  error over its noise floor stands clearly above the others'
  (:mod:`~dynid.identification.differing_recording`).
"""

from __future__ import annotations

from typing import Any

from .html import esc, is_number, number, section, table

__all__ = ["finding_facts", "offsets_section"]


def _meta(doc: Any) -> dict[str, Any]:
    got = doc.get("metadata") if isinstance(doc, dict) else None
    return got if isinstance(got, dict) else {}


def _joint_names(doc: Any) -> list[str]:
    robot = doc.get("robot") if isinstance(doc, dict) else None
    names = robot.get("joint_names") if isinstance(robot, dict) else None
    return [str(x) for x in names] if isinstance(names, list) else []


def _confounded(doc: dict) -> list[str]:
    """Per offset left out that the data cannot tell from another coefficient: the joint,
    the offset fitted beside the model's columns [N m] with its relative standard
    deviation, the coefficient it is correlated with and how much, and the joint's range in
    training."""
    names = _joint_names(doc)
    out = []
    for c in _meta(doc).get("confounded_offsets") or ():
        if not (isinstance(c, dict) and is_number(c.get("joint")) and is_number(c.get("value"))):
            continue
        j = int(c["joint"])
        who = f"joint {j}" + (f" ({names[j - 1]})" if 0 < j <= len(names) else "")
        said = f"{who}: its torque offset {c.get('label', '?')} was left out, but fitted beside "
        said += f"the model's columns it reads {c['value']:.3g} N m"
        if is_number(std := c.get("std_percent")):
            said += f" \u00b1 {std:.3g} %"
        if is_number(rho := c.get("correlation")):
            said += f", correlated {rho:.3f} with {c.get('partner', 'another coefficient')}"
        rng = c.get("position_range")
        if isinstance(rng, list) and len(rng) == 2 and all(map(is_number, rng)):
            said += f"; the joint moved only within {rng[0]:.3g}..{rng[1]:.3g} in training"
        terms = _meta(doc).get("terms")
        kept = (
            f"--terms {','.join(str(t) for t in terms if str(t) != '-' + str(c.get('label')))}"
            if isinstance(terms, list) and terms
            else "--terms with the offset"
        )
        said += (
            ": that coefficient carries whatever offset there is, right at these poses only; "
            f"hint: {kept} keeps the offset, or record poses over a wider range of that joint"
        )
        out.append(f"<b>Offset not told apart</b>: {esc(said)}")
    return out


def _spring(doc: dict) -> list[str]:
    """The spring the held-out residual named and the search run again with it."""
    sel = _meta(doc).get("selection")
    rec = sel.get("spring_candidate") if isinstance(sel, dict) else None
    if not isinstance(rec, dict) or not rec.get("joints"):
        return []
    joints = ", ".join(str(j) for j in rec["joints"])
    said = f"the held-out residual named a joint spring on joint(s) {joints}; the search run "
    with_it, without = rec.get("heldout_error_percent"), rec.get("without_spring_error_percent")
    if not (is_number(with_it) and is_number(without)):
        return [f"<b>Spring trial</b>: {esc(said + 'again with it chose no candidate')}"]
    said += "again with it: " + ("its choice kept" if rec.get("chosen") else "not kept")
    said += f" ({rec.get('structure', '?')}), held out {with_it:.3g} % against "
    said += f"{without:.3g} % without the spring"
    if is_number(se := rec.get("se_vs_spring_percent")) and se > 0:
        said += f", {abs(without - with_it) / se:.2g} standard errors apart"
    said += "" if rec.get("chosen") else " (within one standard error: the simpler kept)"
    return [f"<b>Spring trial</b>: {esc(said)}"]


def _offsets(doc: dict) -> list[str]:
    """The torque offsets that differ between recordings (the summary's note)."""
    rec = _meta(doc).get("recording_offsets")
    if not isinstance(rec, dict) or not isinstance(rec.get("note"), str):
        return []
    return [
        f"<b>Torque offsets per recording</b>: {esc(rec['note'])} "
        '(every offset: <a href="#offsets">table below</a>)'
    ]


def _differing(doc: dict) -> list[str]:
    """Each recording whose held-out error over its noise floor stands clearly above the
    others': its error and floor [%], the others' range."""
    sel = _meta(doc).get("selection")
    out = []
    for d in (sel.get("differing_recordings") if isinstance(sel, dict) else None) or ():
        err, floor = d.get("heldout_error_percent"), d.get("noise_floor_percent")
        if not (isinstance(d, dict) and is_number(err) and is_number(floor) and floor > 0):
            continue
        said = f"{d.get('file', '?')}: held-out error {err:.3g} % ({err / floor:.3g} x its "
        said += f"noise floor of {floor:.3g} %)"
        others = [o for o in d.get("others") or () if isinstance(o, dict)]
        errs = [e for o in others if is_number(e := o.get("heldout_error_percent"))]
        if errs:
            said += f", the other recordings {min(errs):.3g} to {max(errs):.3g} %"
        if is_number(z := d.get("z")):
            said += f" ({z:.2g} standard deviations of theirs above their median)"
        said += (
            ": not outlying, fitted still; its torques differ from theirs (friction that "
            "changed with temperature, another payload or set-up?), and the fit is pulled "
            "towards it; to compare, identify without it"
        )
        out.append(f"<b>A recording differs</b>: {esc(said)}")
    return out


def finding_facts(doc: Any) -> list[str]:
    """The facts (HTML) of ``identification.json``'s findings (module docstring), in the
    order: offsets not told apart, offsets per recording, a differing recording, the
    spring trial; empty where it holds none."""
    if not isinstance(doc, dict):
        return []
    return _confounded(doc) + _offsets(doc) + _differing(doc) + _spring(doc)


def offsets_section(doc: Any) -> str:
    """The titled table of the torque offsets fitted one per recording
    (``metadata.recording_offsets``): a row per recording, a column per joint whose
    offsets differ (value and standard deviation [N m]), and the mean and tolerance
    rows; empty without."""
    rec = _meta(doc).get("recording_offsets") if isinstance(doc, dict) else None
    if not isinstance(rec, dict):
        return ""
    files, joints = rec.get("recordings"), rec.get("joints")
    offsets, std = rec.get("offsets"), rec.get("std")
    if not (isinstance(files, list) and isinstance(joints, list) and isinstance(offsets, list)):
        return ""
    names = _joint_names(doc)
    cols = [names.index(j) if j in names else -1 for j in joints]
    if any(k < 0 for k in cols) or len(offsets) != len(files):
        return ""

    def value(row: Any, k: int, spread: Any = None) -> str:
        v = row[k] if isinstance(row, list) and k < len(row) else None
        if not is_number(v):
            return ""
        s = spread[k] if isinstance(spread, list) and k < len(spread) else None
        return number(v) + (f" &plusmn; {number(s, 2)}" if is_number(s) else "")

    std = std if isinstance(std, list) and len(std) == len(files) else [None] * len(files)
    rows = [
        [esc(f)] + [value(o, k, s) for k in cols]
        for f, o, s in zip(files, offsets, std, strict=True)
    ]
    for label, key in (("mean", "mean"), ("tolerance", "tolerance")):
        if isinstance(rec.get(key), list):
            rows.append([label] + [value(rec[key], k) for k in cols])
    heads = ["recording", *(f"{j} offset [N m]" for j in joints)]
    said = (
        "<p>Each recording's torque offset, fitted one per recording and joint, &plusmn; the "
        "standard error of its difference from the mean; mean: the sample-weighted mean, the "
        "model's offset (a new recording's, as the model predicts it); tolerance: the size a "
        "difference must exceed to count.</p>"
    )
    return section("offsets", "Torque offsets per recording", said, table(heads, rows))
