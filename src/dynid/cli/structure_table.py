"""The table of the model structures judged on held-out data, as ``identify`` prints it."""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

from ..identification.determined import determined_sentence

__all__ = ["estimator_lines", "per_recording_lines", "selection_lines", "text_width"]


def text_width(header: str, cells: Any, least: int = 0) -> int:
    """The width of a left-aligned column: its header's, its longest cell's, or ``least``."""
    return max([least, len(header), *(len(str(c)) for c in cells)])


def selection_lines(selection: Any) -> list[str]:
    """The model structures judged on held-out data, the one kept marked ``*``, those
    skipped because their friction is not dissipative or their Stribeck bump is below zero
    ``x`` (one note says why)."""
    if not selection:
        return []
    # a per-joint structure's coefficients left out go last ("- fo1 - fc4"), so that the
    # table is as wide as the structures' names without them
    split = [str(c["name"]).partition(" - ") for c in selection["candidates"]]
    # the per-joint search's every coefficient left out: a part left out on every joint
    # is gone from the name (``viscous``) and listed here (``fv1-7``)
    split = [
        (name, _, " - ".join(c.get("left_out") or ()) or dropped)
        for c, (name, _, dropped) in zip(selection["candidates"], split, strict=True)
    ]
    # the choice reads the held-out error with each joint in units of its own noise
    white = any(c.get("heldout_whitened_percent") is not None for c in selection["candidates"])
    cands = selection["candidates"]
    # skipped (not dissipative within the velocity limits) unless every candidate is
    skip = not all(_skipped(c) for c in cands)
    # the candidates skipped, marked x as the selection's note says: each law's best shown
    marked = {str(c["name"]) for c in cands if skip and _skipped(c)}
    shown, hidden, hidden_marked = _best_of_shapes(cands, selection["chosen"], marked)
    split = _told_apart(split, [c["name"] in shown for c in cands])
    w = text_width("structure", [name for name, _, _ in split], 46)
    # the column of the coefficients left out, when a row shown holds some
    left = any(d for c, (_, _, d) in zip(cands, split, strict=True) if c["name"] in shown)
    out = [
        f"model structure chosen on held-out data ({selection['validation']}): "
        f"{selection['chosen']} ({selection['rule']})",
        *_own_offsets_line(selection.get("heldout_own_offsets") or ()),
        *_determined_line(selection.get("kept_determined") or ()),
        f"    {'structure':<{w}} {'params':>6} {'train %':>9} {'held-out %':>11}"
        + (f" {'whitened %':>11}" if white else "")
        + f" {'se vs best':>10}"
        + ("  coefficients left out" if left else ""),
    ]
    for c, (name, _, dropped) in zip(cands, split, strict=True):
        if c["name"] not in shown:
            continue
        mark = "*" if c["name"] == selection["chosen"] else " "
        mark = "x" if skip and _skipped(c) else mark
        out.append(
            f"  {mark} {name:<{w}} {c['n_params']:>6} {c['train_error_percent']:>9.4g} "
            f"{c['heldout_error_percent']:>11.4g}"
            + (f" {_or_nan(c.get('heldout_whitened_percent')):>11.4g}" if white else "")
            + f" {_se_vs_best(c):>10}"
            + (f"  {_compact(dropped.split(' - '))}" if dropped and left else "")
        )
    if hidden:
        out.append(
            f"  ({hidden} more candidate(s) of a smooth or Stribeck law at other widths or "
            "Stribeck velocities"
            + (f", {hidden_marked} of them marked x" if hidden_marked else "")
            + ": the table shows each law's best, of those skipped (x) too; "
            "metadata.selection.candidates holds every one)"
        )
    out += per_recording_lines(selection, "  ")
    out += [f"  note: {line}" for line in selection.get("notes", ())]
    return out


def _own_offsets_line(joints: Sequence[str]) -> list[str]:
    """Under the table's header, where the recordings' torque offsets were fitted one per
    recording (``joints``: those whose offsets differ), that its held-out errors read each
    held-out recording with its own offset there."""
    if not joints:
        return []
    return [
        "  held-out errors below with each held-out recording's own torque offset on "
        f"{len(joints)} joint(s) (fitted one per recording: the note on the offsets above); "
        "a new recording's offset is unknown to the model, its error higher"
    ]


def per_recording_lines(record: Any, indent: str = "", given: bool = False) -> list[str]:
    """The structure's held-out error per recording, fitted on the others, those outlying
    marked, and those whose spans were cut out (``cut_out_spans``: the error of the rest)
    (``record``: ``metadata.selection``, or ``metadata`` of a structure ``given``);
    none when it holds none."""
    per = record.get("heldout_per_recording") or () if isinstance(record, dict) else ()
    if not per:
        return []
    odd = set(record.get("outlying_recordings") or ())
    cut = {c.get("file") for c in record.get("cut_out_spans") or () if isinstance(c, dict)}
    return [
        f"{indent}held-out error of the {'structure given' if given else 'chosen structure'} "
        "per recording (fitted on the others): "
        + ", ".join(
            f"{r['file']} {r['heldout_error_percent']:.3g} %"
            + (" (outlying: its spans cut out)" if r["file"] in cut else "")
            + (" (outlying)" if r["file"] in odd - cut else "")
            for r in per
        )
    ]


def estimator_lines(choice: Any) -> list[str]:
    """The estimators judged on the chosen structure's held-out folds
    (``metadata.estimator_choice``), the one kept marked ``*``: one line each."""
    if not choice:
        return []
    cands = choice["candidates"]
    out = [f"estimator chosen on the same held-out data: {choice['chosen']} ({choice['rule']})"]
    out.append(
        f"    {'estimator':<9} {'train %':>9} {'held-out %':>11} {'whitened %':>11} "
        f"{'se vs best':>10}"
    )
    for c in cands:
        mark = "*" if c["estimator"] == choice["chosen"] else " "
        out.append(
            f"  {mark} {c['estimator']:<9} {c['train_error_percent']:>9.4g} "
            f"{c['heldout_error_percent']:>11.4g} {_or_nan(c['heldout_whitened_percent']):>11.4g} "
            f"{_se_vs_best(c):>10}"
        )
    return out


def _or_nan(x: float | None) -> float:
    """``x``, or nan for None (not known; a held-out error of 0 is one)."""
    return float("nan") if x is None else float(x)


def _told_apart(
    split: list[tuple[str, str, str]], shown: Sequence[bool]
) -> list[tuple[str, str, str]]:
    """The rows' (name, separator, coefficients left out), a per-joint structure's name
    told from another row ``shown`` of the same name (its every joint's coefficients) by
    ``, per joint``: the coefficients left out go to their own column, and the two rows
    read alike (FR3, two recordings: ``links + viscous + smooth:10 + stribeck:0.0803 +
    offset`` twice, 71 and 65 parameters)."""
    names = [name for (name, _, _), on in zip(split, shown, strict=True) if on]
    return [
        (f"{name}, per joint" if dropped and names.count(name) > 1 else name, sep, dropped)
        for name, sep, dropped in split
    ]


def _determined_line(kept: Sequence[dict[str, Any]]) -> list[str]:
    """The coefficients kept because the data determine them although the held-out error
    would not miss them (:func:`~dynid.identification.candidates.determined_sentence`)."""
    said = determined_sentence(kept)
    return [] if said is None else ["  " + said]


def _best_of_shapes(
    cands: Sequence[dict[str, Any]], chosen: str, marked: set[str]
) -> tuple[set[str], int, int]:
    """The names of the candidates the table shows, how many it leaves out and how many
    of those are ``marked`` (skipped, x): of the candidates that differ only in a shape
    (``smooth:0.3`` and ``smooth:1``, ``stribeck:0.05``, ``stribeck:0.1`` and
    ``stribeck:0.08/0.1/...``, one per joint), the one with
    the lowest held-out error, among those skipped and among the others apart (an iiwa's
    table showed 37 rows marked x of 57, seven shapes each of six laws); every other
    candidate, and the one chosen."""
    best: dict[tuple[str, bool], dict[str, Any]] = {}
    for c in cands:
        family = re.sub(r"smooth:[0-9.eE+-]+", "smooth:*", str(c["name"]))
        family = re.sub(r"stribeck:[0-9.eE+/-]+", "stribeck:*", family)
        key = (family, str(c["name"]) in marked)
        if key not in best or c["heldout_error_percent"] < best[key]["heldout_error_percent"]:
            best[key] = c
    shown = {str(c["name"]) for c in best.values()} | {chosen}
    hidden = [str(c["name"]) for c in cands if c["name"] not in shown]
    return shown, len(hidden), sum(1 for name in hidden if name in marked)


def _se_vs_best(c: dict[str, Any]) -> str:
    """The standard error of a candidate's held-out error's difference from the lowest
    (paired over the folds), blank where there is none (the best, one fold); files
    written before it was recorded give each candidate's own standard error."""
    se = c.get("heldout_se_vs_best_percent", c.get("heldout_se_percent"))
    return f"{se:.2g}" if se else ""


def _compact(labels: list[str]) -> str:
    """``fv1 fv2 fv3 fo2`` as ``fv1-3 fo2``: each coefficient's joints, runs joined."""
    joints: dict[str, list[int]] = {}
    for lab in labels:
        stem = lab.rstrip("0123456789")
        if stem == lab:
            joints.setdefault(lab, [])
            continue
        joints.setdefault(stem, []).append(int(lab[len(stem) :]))
    out = []
    for stem, js in joints.items():
        if not js:
            out.append(stem)
            continue
        js = sorted(set(js))
        runs: list[list[int]] = [[js[0]]]
        for j in js[1:]:
            if j == runs[-1][-1] + 1:
                runs[-1].append(j)
            else:
                runs.append([j])
        for r in runs:
            out += [f"{stem}{r[0]}-{r[-1]}"] if len(r) > 2 else [f"{stem}{j}" for j in r]
    return " ".join(out)


def _skipped(candidate: dict) -> bool:
    """Whether the choice skips a candidate: friction not dissipative, or a Stribeck bump
    below zero."""
    return bool(candidate.get("not_dissipative") or candidate.get("negative_bump"))
