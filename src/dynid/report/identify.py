"""The answer of ``dynid identify``: is the model good enough, and how sure are we.

The verdict (at the noise floor, usable, poor, unusable: :mod:`dynid.identification.verdict`)
is ``heldout.json``'s, the one the command prints: the held-out block's error against the
noise of its sensors and of its states through the model, each sample against its own
(:mod:`dynid.identification.floor_verdict`). For an older file it weighs the held-out error
against the sensor-noise floor of the torques it was judged on
(``metadata.heldout``: the floor the command prints; for an older record without one,
``heldout.json``'s: the last time block predicted by the fit of the others, unfiltered
torques with their one-sample spikes replaced as the fit replaced them, against the noise
read from the log), the training against the held-out error
(over-fitting), the rank against the columns of the model (the base parameters are the
structural rank of the kinematics), and the relative standard deviations (the paper pruned
above 30 %). A one-step consistent fit (``identify --consistent``: ``report.json``'s
``heldout``) is the result asked for: the headline is its held-out error against the
noise floor of the torques it was judged on, least squares' the comparison. Below it: the
measured against the predicted torques on held-out data, the residuals, the model
structure (``selection``, when the identification chose terms), the coefficients with their
standard deviations as bars, and each appended term (friction at the motors and at the
joints, armature: :mod:`.model_terms`).
"""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np

from ..exceptions import DynidError
from ..identification.determined import determined_sentence
from ..identification.selection import DISAGREE_NOTE
from ..identification.structure import Structure
from ..identification.verdict import (
    FLOOR_GOOD,
    LEVELS,
    Verdict,
    joint_levels,
    joint_ratios,
    judge_prediction,
    with_caveat,
    worst,
)
from .constants import constants_facts
from .delay import delay_facts, delay_section
from .html import (
    bar,
    capitalised,
    cell,
    esc,
    figure,
    file_unit,
    is_number,
    number,
    percent,
    section,
    table,
    verdict,
)
from .identify_findings import finding_facts, offsets_section
from .model_terms import terms_sections
from .motion import outside_section
from .run import Answer, RunFiles
from .springs import spring_facts, springs_section

__all__ = ["answer", "coefficient_unit"]

#: Relative standard deviation [%] above which a coefficient counts as poorly identified
#: (the threshold Gaz et al. 2019 pruned at).
UNCERTAIN_PERCENT = 30.0
#: Held-out / training error above which the model over-fits (usable up to OVERFIT_FAIR).
OVERFIT_GOOD, OVERFIT_FAIR = 1.1, 1.5
#: Figures of the identification (written by the command when it has torques).
FIGURES = (
    ("heldout_torques.png", "Measured and predicted torques on held-out data"),
    ("heldout_residuals.png", "Residuals on held-out data, per joint"),
)


def coefficient_unit(expression: str) -> str:
    """The SI unit of a base parameter from its expression: kg m^2 when it holds an
    inertia (``J``, ``Ia``), kg m for a first moment (``mc``), kg for masses."""
    if re.search(r"\b(J\d|Ia\d)", expression):
        return "kg m^2"
    if re.search(r"\bmc\d", expression):
        return "kg m"
    if re.search(r"\bm\d", expression):
        return "kg"
    return ""


def _get(doc: Any, *keys: str) -> Any:
    for k in keys:
        if not isinstance(doc, dict):
            return None
        doc = doc.get(k)
    return doc


def _heldout_facts(
    doc: dict, held: dict | None, contradicted: bool = False, *, floor_fact: bool = True
) -> tuple[list[str], list[str], str]:
    """(facts, problems, headline) of the held-out judgement: the record's held-out error
    against the record's sensor-noise floor (``metadata.heldout``: the numbers the command
    prints; its fact left out without ``floor_fact``, where another fit's states the
    floor), each joint against its noise as ``validate`` judges (``heldout.json``'s
    per-joint errors); the last block's unfiltered error beside it, against a floor of its
    own only for a record without one (an older file). ``contradicted``: the data
    contradict the robot (:func:`_warning_facts`), which makes the verdict unusable
    whatever the errors, and the held-out fact says so instead of its own level. A
    heldout.json judged against the held-out states' noise too (:func:`_own_verdict`)
    gives the verdict itself, the one the command printed."""
    facts, problems = [], []
    ho = _get(doc, "metadata", "heldout")
    train, test = _get(ho, "training_error_percent"), _get(ho, "heldout_error_percent")
    floor = _get(ho, "noise_floor_percent")
    judged = None  # the record's held-out error against its floor
    caveat = ho.get("caveat") if isinstance(ho, dict) else None
    own = _own_verdict(held)
    if own is not None:  # the block judged against its own floor, as the command printed
        judged = own
    elif is_number(test) and is_number(floor) and floor > 0:
        judged = _heldout_verdict(held, test, floor) if held else judge_prediction(test, floor)
        judged = with_caveat(judged, caveat)
    block = held is not None and is_number(held.get("relative_error_percent"))
    if judged is not None:
        at_floor = judged.ratio is not None and judged.ratio <= FLOOR_GOOD
    elif block:
        assert held is not None
        bf = held.get("noise_floor_percent")
        at_floor = is_number(bf) and bf > 0
        at_floor = at_floor and held["relative_error_percent"] / bf <= FLOOR_GOOD
    else:
        at_floor = False
    headline = ""
    bf = held.get("noise_floor_percent") if held is not None else None
    floored = judged is not None or (block and is_number(bf) and bf > 0)
    if is_number(train) and is_number(test):
        per_row = _parameters_per_row(doc)
        fact, more = _overfit_fact(ho, train, test, at_floor, per_row, judged=floored)
        facts.append(fact)
        problems += more
        headline = f"The model predicts held-out torques to {percent(test)}"
    if own is not None:
        assert held is not None
        more_facts, more, headline = _own_facts(held, own, contradicted, isinstance(caveat, str))
        return facts + more_facts, problems + more, headline
    if judged is not None:
        fact, more, headline = _floor_fact(
            judged, test, floor, "torques it was judged on", contradicted,
            within_motion=isinstance(caveat, str), samples=pooled_label(ho),
        )  # fmt: skip
        facts += [fact] if floor_fact else []
        problems += more
    if block:
        assert held is not None
        fact, more, said = _block_fact(held, judged is None, contradicted)
        facts.append(fact)
        problems += more
        headline = said or headline
        low = held.get("low_speed")
        if isinstance(low, str) and low:  # where the rest of the error sits
            facts.append(esc(capitalised(low)))
    elif headline and judged is None:
        facts.append(
            "Sensor-noise floor not measured (heldout.json absent: the run was made with "
            "--no-figures, or the log could not be read back)"
        )
    return facts, problems, headline


def _own_facts(
    held: dict, own: Verdict, contradicted: bool, within_motion: bool
) -> tuple[list[str], list[str], str]:
    """(facts, problems, headline) of heldout.json's own verdict (:func:`_own_verdict`):
    the block's unfiltered error against its noise floor (the sensors' and the states'),
    the torque spikes replaced before judging and the low-speed note."""
    fact, problems, headline = _floor_fact(
        own,
        held["relative_error_percent"],
        held["noise_floor_percent"],
        "unfiltered held-out torques",
        contradicted,
        within_motion=within_motion,
        what="noise floor",
        above=_above_noise(held),
        samples=verdict_samples(held),
    )
    block = esc(str(held.get("block", "held-out data")))
    said = f"{fact[0].lower()}{fact[1:]}"
    facts = [f"Held-out verdict on {block} (every sample, torques as measured): {said}"]
    spikes = held.get("torque_spikes_replaced")
    if is_number(spikes) and spikes > 0 and SPIKES_SAID not in own.reason:  # said once
        facts.append(f"{int(spikes)} one-sample torque spike(s) replaced, as the fit replaced them")
    low = held.get("low_speed")
    if isinstance(low, str) and low:  # where the rest of the error sits
        facts.append(esc(capitalised(low)))
    facts += constants_facts(held)  # a current log's: which constants the data check
    return facts, problems, headline


#: Words of a verdict's reason that say it was judged with torque spikes replaced
#: (:func:`~dynid.identification.verdict.with_replaced_spikes`): the page says it once.
SPIKES_SAID = "torque spike(s) replaced"


def _above_noise(held: dict) -> str:
    """The joints of heldout.json judged above their noise
    (:func:`~dynid.identification.verdict.joint_levels`: beyond
    :data:`~dynid.identification.verdict.SYSTEMATIC_RATIO` x it), in words
    (``"right_s1 at 2.43 x its noise (0.738 N m RMS)"``), or ``""``."""
    rms, noise, names = held.get("rms"), held.get("noise_rms"), held.get("joint_names")
    if not (isinstance(rms, list) and isinstance(noise, list) and isinstance(names, list)):
        return ""
    if not len(rms) == len(noise) == len(names) or not all(map(is_number, rms + noise)):
        return ""
    r = _held_ratios(held, rms, noise)
    s, i = held.get("sensor_noise_rms"), held.get("input_noise_rms")
    rough = None
    if isinstance(s, list) and isinstance(i, list) and len(s) == len(i) == len(r):
        rough = [is_number(a) and is_number(b) and b > a for a, b in zip(s, i, strict=True)]
    per = held.get("relative_error_percent_per_joint")
    per = per if isinstance(per, list) and len(per) == len(r) and all(map(is_number, per)) else None
    levels = joint_levels(per, r, rough)
    said = [
        f"{names[j]} at {r[j]:.3g} x its noise ({float(rms[j]):.3g} N m RMS)"
        for j in np.argsort(-r)
        if levels[j] != "good"
    ]
    if not said:
        return ""
    gains = _gains_words(held.get("drive_gains"))
    return ", ".join(said) + (
        f" (a systematic residual: {gains})" if gains else " (a systematic residual)"
    )


def _gains_words(gains: object) -> str:
    """The gains finding of heldout.json's ``drive_gains`` in a few words, its first
    named factor first (``"the torque constants look off: that of motor 1 looks 0.667 times
    the true one (multiply it by 1.5), and 1 more"``, as the summary says it), or ``""``
    when it names none."""
    if not isinstance(gains, dict):
        return ""
    named, factor = gains.get("named"), gains.get("factor")
    if not (isinstance(named, list) and named and isinstance(factor, list)):
        return ""
    k = named[0]
    if not (isinstance(k, int) and 0 <= k < len(factor) and is_number(factor[k])):
        return ""
    current = gains.get("effort") == "current"
    unit = str(gains.get("per", "motor" if current else "joint"))
    f = float(factor[k])
    if not gains.get("scaled", True):
        what = "torque constants" if current else "torques"
        said = f"the {what} look off by different factors: {unit} {k + 1} by {f:.3g} of the others"
    elif current:
        said = (
            f"the torque constants look off: that of {unit} {k + 1} looks {1 / f:.3g} times "
            f"the true one (multiply it by {f:.3g})"
        )
    else:
        said = (
            f"the torques of {unit} {k + 1} read {1 / f:.3g} times the true ones (scale by {f:.3g})"
        )
    more = len(named) - 1
    return said + (f", and {more} more" if more else "")


def _held_ratios(held: dict, rms: list, noise: list) -> np.ndarray:
    """Each joint's held-out error over its noise as the verdict weighed it (heldout.json
    ``joint_ratios``: each sample against its own noise, the numbers of the verdict's
    reason), or, in a file without them, the RMS error over ``noise_rms``
    (:func:`~dynid.identification.verdict.joint_ratios`)."""
    got = held.get("joint_ratios")
    if isinstance(got, list) and len(got) == len(rms) and all(map(is_number, got)):
        return np.asarray(got, dtype=np.float64)
    return joint_ratios(rms, noise)


def _parameters_per_row(doc: dict) -> float | None:
    """The fit's coefficients over its rows (``metadata.n_rows``), or None."""
    rows = _get(doc, "metadata", "n_rows")
    if not (is_number(rows) and rows > 0):
        return None
    labels = _get(doc, "metadata", "friction_labels")
    p = len(doc.get("coefficients") or []) + (len(labels) if isinstance(labels, list) else 0)
    return p / rows


#: Coefficients per row below which a fit cannot over-fit noticeably (least squares on
#: white noise: held-out over training error about 1 + p / m).
FEW_PARAMETERS_PER_ROW = 0.01


def _overfit_fact(
    ho: dict,
    train: float,
    test: float,
    at_floor: bool,
    per_row: float | None = None,
    *,
    judged: bool = False,
) -> tuple[str, list[str]]:
    """The training against the held-out error (over-fitting), and its problem. With few
    coefficients per row (``per_row`` below :data:`FEW_PARAMETERS_PER_ROW`) a gap between
    recordings left out in turn is not over-fitting: the recordings hold effects outside
    the model that differ between them (the held-out error against the floor judges it).
    ``judged``: a held-out verdict against a noise floor is on the page (the headline's);
    the ratio is then a check of extrapolation to the data left out, which an effect
    outside the model that changes over time (a spring, a drift) fails as over-fitting
    does: it is said as that check and leaves the level to the verdict, which has already
    weighed the held-out error, over-fitting or not (one story on the page). The error is
    given beside its own floor, the measured torques' noise over the same samples
    (``noise_floor_percent``), as the command's summary gives it."""
    scheme = {
        "blocks": f"over {ho.get('folds')} contiguous time blocks",
        "recordings": f"leaving out each of {ho.get('folds')} recordings in turn",
    }.get(str(ho.get("scheme")), "on the separate log")
    ratio = test / train if train > 0 else 1.0
    few = per_row is not None and per_row < FEW_PARAMETERS_PER_ROW
    left_out = {"blocks": "time blocks", "recordings": "recordings"}.get(
        str(ho.get("scheme")), "data"
    )
    if ratio <= OVERFIT_GOOD:
        why = "no sign of over-fitting"
    elif few:
        why = (
            f"not over-fitting, {per_row:.2g} coefficients per row: the "
            + ("recordings" if ho.get("scheme") == "recordings" else "held-out data")
            + " hold effects outside the model that differ from the training data's"
        )
    elif at_floor:  # the fit follows some noise, and predicts as well as noise allows
        why = "the fit follows some of the noise, yet predicts to the noise floor below"
    elif judged:  # the verdict judges the model; this checks extrapolation
        why = (
            f"a check of extrapolation: the {left_out} left out are predicted worse than "
            "those fitted, by over-fitting or by an effect outside the model that changes "
            f"over the {left_out} (the joints named above); it does not set the verdict: "
            "the held-out verdict in the headline weighs the held-out error against the "
            "noise floor"
        )
    else:
        why = "the fit over-fits"
    floor = ho.get("noise_floor_percent")
    own = (  # its own floor, beside it: not the verdict's (another error, other samples)
        f"; the measured torques' noise there {percent(floor)}"
        if is_number(floor) and floor > 0
        else ""
    )
    fact = (
        f"Held-out error of least squares <b>{percent(test)}</b> {esc(scheme)} "
        f"({esc(pooled_label(ho))}{esc(own)}), training error {percent(train)} on the same (ratio "
        f"{ratio:.2f}: {esc(why)})"
    )
    if few or at_floor or judged:
        return fact, []
    if ratio > OVERFIT_FAIR:
        return fact, ["poor"]
    return fact, ["fair"] if ratio > OVERFIT_GOOD else []


def verdict_samples(held: dict | None) -> str:
    """What the held-out verdict's error is computed on (heldout.json's, the command's
    verdict): every sample of the held-out recordings (each left out in turn, or the
    last), of the separate log (``--validate-on``) or of the held-out time block, torques
    as measured; read from heldout.json's ``block``, which names them. Before, whole
    recordings left out in turn were called "the held-out block"."""
    block = str((held or {}).get("block", ""))
    where = (
        "the held-out recordings"
        if "recordings" in block
        else "the separate log"
        if "--validate-on" in block
        else "the held-out block"
    )
    return f"every sample of {where}, torques as measured"


def pooled_label(ho: Any) -> str:
    """What least squares' held-out error of the record (``metadata.heldout``) is computed
    on: the fit's own rows, filtered and decimated, pooled over the folds where there are
    several (a figure apart from the verdict's, :func:`verdict_samples`)."""
    folds = isinstance(ho, dict) and ho.get("scheme") in ("blocks", "recordings")
    return "filtered, decimated samples" + (", pooled over the folds" if folds else "")


def _floor_fact(
    v: Verdict,
    err: float,
    floor: float,
    torques: str,
    contradicted: bool = False,
    *,
    within_motion: bool = False,
    what: str = "sensor-noise floor",
    above: str = "",
    samples: str = "",
) -> tuple[str, list[str], str]:
    """(fact, problems, headline) of an error against a noise floor, ``what`` it is (the
    joints the verdict names, or why it was reached; unusable where the data contradict the
    robot; ``within_motion``: judged on blocks of the motion the model was fitted to, which
    test too little, :func:`~dynid.identification.least_squares.within_motion_caveat`);
    ``above``: the joints above their own noise in words, said in the headline;
    ``samples``: what the error is computed on, said beside it in the headline with the
    verdict's label (a verdict the command printed)."""
    r = v.ratio if v.ratio is not None else math.inf
    joints = "joint(s) " + v.reason.split("; joint(s) ", 1)[1] if "; joint(s) " in v.reason else ""
    said = (
        "<b>unusable</b>: the data contradict the robot (below), whatever the error"
        if contradicted
        else f"<b>{esc(v.label)}</b>: " + esc(joints or v.reason.split("): ", 1)[-1])
    )
    fact = (
        f"Error {percent(err)} against a {what} of {percent(floor)} of the "
        f"{esc(torques)} (<b>{r:.3g} x the floor</b>): {said}"
    )
    level = "at" if r <= FLOOR_GOOD and not above else f"{r:.3g} times"  # as in the fact
    said_level = f" (held-out verdict: {esc(v.label)})" if samples and v.level != "good" else ""
    headline = (
        f"The model predicts held-out torques to {percent(err)}"
        + (f" ({esc(samples)})" if samples else "")
        + f", {level} the {what} of {percent(floor)}{said_level}"
        + (f"; {esc(above)}" if above else "")
    )
    if contradicted:
        headline = (
            f"The data contradict the robot (below): a held-out error of {percent(err)} "
            "cannot be trusted"
        )
    elif v.unusable:
        headline = f"The model does not explain held-out torques: error {percent(err)}"
    elif within_motion:  # held-out data that test too little
        headline += " on held-out blocks of the motion it was fitted to"
    return fact, [] if v.level == "good" else [v.level], headline


def _block_fact(held: dict, judge: bool, contradicted: bool = False) -> tuple[str, list[str], str]:
    """(fact, problems, headline or "") of the last block's unfiltered error
    (``heldout.json``, the figures' and the table's data): against its own floor when
    ``judge`` (a record without one), else the error alone (the floor is the record's)."""
    err, floor = held["relative_error_percent"], held.get("noise_floor_percent")
    where = f"On {esc(held.get('block', 'held-out data'))}, unfiltered"
    spikes = held.get("torque_spikes_replaced")
    if is_number(spikes) and spikes > 0:  # replaced before judging, as before the fit
        where += f" ({int(spikes)} one-sample torque spike(s) replaced, as the fit replaced them)"
    if not judge:
        v = judge_prediction(err)  # only a model that explains nothing is judged here
        fact = f"{where} (the figures and the table below): error {percent(err)}"
        bad = v.unusable
        return (
            fact,
            ["unusable"] if bad else [],
            (f"The model does not explain held-out torques: error {percent(err)}" if bad else ""),
        )
    floor = floor if is_number(floor) else None
    v = _heldout_verdict(held)
    if v.ratio is None or floor is None:
        fact = f"{where}: error {percent(err)} (noise floor unknown): " + (
            "<b>unusable</b>: the data contradict the robot (below)"
            if contradicted
            else f"<b>{esc(v.label)}</b>: {esc(v.reason)}"
        )
        return (
            fact,
            [] if v.level == "good" else [v.level],
            (
                f"The model does not explain held-out torques: error {percent(err)}"
                if v.unusable
                else ""
            ),
        )
    fact, problems, headline = _floor_fact(v, err, floor, "unfiltered torques", contradicted)
    return (
        f"{where}: {fact[0].lower()}{fact[1:]}",
        problems,
        headline + ("" if v.unusable else " (unfiltered torques)"),
    )


def _own_verdict(held: dict | None) -> Verdict | None:
    """heldout.json's own verdict, made against the floor of the sensors' and the held-out
    states' noise, each sample against its own (a file with ``sensor_noise_rms``; the
    ratio cannot be re-derived from the file's sums): the verdict the command printed, or
    None for an older file."""
    if not isinstance(held, dict) or "sensor_noise_rms" not in held:
        return None
    v, err, floor = (
        held.get("verdict"),
        held.get("relative_error_percent"),
        held.get("noise_floor_percent"),
    )
    if not (isinstance(v, dict) and v.get("level") in LEVELS and is_number(err)):
        return None
    if not is_number(floor):
        return None
    ratio = v.get("ratio")
    return Verdict(
        v["level"],
        str(v.get("label") or v["level"]),
        str(v.get("reason", "")),
        float(ratio) if is_number(ratio) else None,
    )


def _heldout_verdict(held: dict, err: float | None = None, floor: float | None = None) -> Verdict:
    """heldout.json judged as ``validate`` judges a log (the pooled error against the floor,
    each joint against its noise and in relative terms), from the file's numbers; the
    pooled error and floor ``err``, ``floor`` [%] when given (the record's)."""
    if err is None:
        err, floor = held["relative_error_percent"], held.get("noise_floor_percent")
    rms, noise = held.get("rms"), held.get("noise_rms")
    per = held.get("relative_error_percent_per_joint")
    names = held.get("joint_names")

    def numbers(x: Any) -> list[float] | None:
        ok = isinstance(x, list) and x and all(is_number(v) or v is None for v in x)
        return [float("nan") if v is None else float(v) for v in x] if ok else None

    rms, noise, per = numbers(rms), numbers(noise), numbers(per)
    ratios = _held_ratios(held, rms, noise) if rms and noise and len(rms) == len(noise) else None
    if per is not None and ratios is not None and len(per) != len(ratios):
        per = None
    n = len(per) if per is not None else (len(ratios) if ratios is not None else 0)
    return judge_prediction(
        err,
        floor if is_number(floor) else None,
        joint_ratios=ratios,
        joint_percent=per,
        joint_rms=rms if ratios is not None else None,
        joint_names=[str(x) for x in names]
        if isinstance(names, list) and len(names) == n
        else None,
    )


def _consistent_heldout(run: RunFiles) -> dict | None:
    """The held-out judgement of a one-step consistent fit (``report.json``'s ``heldout``:
    its errors and least squares' on the same folds), or None without one."""
    ho = _get(run.doc("report.json"), "heldout")
    errors = [_get(ho, f, k) for f in ("consistent", "least_squares") for k in _ERRORS]
    return ho if all(is_number(e) for e in errors) else None


#: The errors [%] of a fit in the held-out judgement's records.
_ERRORS = ("training_error_percent", "heldout_error_percent")


def _consistent_facts(doc: dict, ho: dict) -> tuple[list[str], list[str], str]:
    """(facts, problems, headline) of the consistent fit the user asked for
    (``identify --consistent``): its held-out error first, against the sensor-noise floor
    of the torques it was judged on (``metadata.heldout.noise_floor_percent``, the one the
    command prints), least squares' on the same folds as the comparison."""
    train, test = (ho["consistent"][k] for k in _ERRORS)
    ls_train, ls_test = (ho["least_squares"][k] for k in _ERRORS)
    scheme = {
        "blocks": f"over {ho.get('folds')} contiguous time blocks",
        "recordings": f"leaving out each of {ho.get('folds')} recordings in turn",
    }.get(str(ho.get("scheme")), "on the separate log")
    facts = [
        f"Held-out error of the consistent fit <b>{percent(test)}</b> {esc(scheme)} "
        f"({esc(pooled_label(ho))}), training error {percent(train)}; least squares, for "
        f"comparison: held-out {percent(ls_test)}, training {percent(ls_train)}"
    ]
    headline = (
        f"The consistent fit predicts held-out torques to {percent(test)} (least squares: "
        f"{percent(ls_test)}; both on {pooled_label(ho)})"
    )
    floor = _get(doc, "metadata", "heldout", "noise_floor_percent")
    v = judge_prediction(test, floor if is_number(floor) and floor > 0 else None)
    problems: list[str] = [] if v.level == "good" else [v.level]
    if v.ratio is not None:
        level = "at" if v.ratio <= FLOOR_GOOD else f"{v.ratio:.3g} times"
        headline += f", {level} the sensor-noise floor of {percent(floor)}"
        facts.append(
            f"Consistent fit: <b>{v.ratio:.3g} x the sensor-noise floor</b> of "
            f"{percent(floor)} of the torques it was judged on ({esc(v.label)})"
        )
    if v.unusable:
        headline = f"The consistent fit does not explain held-out torques: error {percent(test)}"
    return facts, problems, headline


def _static_facts(doc: dict) -> tuple[list[str], list[str], str]:
    err = doc.get("relative_error_percent")
    noise = _get(doc, "metadata", "data", "relative_noise")
    if not is_number(err):
        return [], [], ""
    if is_number(noise):
        floor = 100.0 * noise
        ok = err <= max(3.0 * floor, 1e-6)
        fact = (
            f"Relative error of M(q), g(q) <b>{percent(err)}</b> on data recorded with relative "
            f"noise {percent(floor)} ("
            + (
                ("noise-free data fit to rounding)" if floor == 0 else "explained by the noise)")
                if ok
                else "more than the noise explains)"
            )
        )
        return (
            [fact],
            [] if ok else ["poor"],
            f"The model reproduces M(q) and g(q) to {percent(err)}",
        )
    fact = f"Relative error of M(q), g(q) <b>{percent(err)}</b> (noise level not recorded)"
    return [fact], ["fair"], f"The model reproduces M(q) and g(q) to {percent(err)}"


def _rank_fact(doc: dict) -> tuple[str, list[str]]:
    coefs = doc.get("coefficients") or []
    friction = _get(doc, "metadata", "friction_labels") or []
    columns = len(coefs) + len(friction)
    rank, base = doc.get("rank"), _get(doc, "base", "rank")
    labels, own = _get(doc, "base", "std_labels"), _get(doc, "base", "independent")
    rotors = (
        sum(1 for k in own if 0 <= k < len(labels) and str(labels[k]).startswith("Ia"))
        if isinstance(labels, list) and isinstance(own, list)
        else 0
    )
    of_them = f"; {rotors} of them rotor inertias (armatures) of their own" if rotors else ""
    parts = f"{base} base parameters (the structural rank of the kinematics{of_them})"
    offsets = [x for x in friction if str(x).rstrip("0123456789").removeprefix("j") == "fo"]
    if len(friction) > len(offsets):
        parts += f" + {len(friction) - len(offsets)} friction"
    if offsets:
        parts += f" + {len(offsets)} offset"
    if not is_number(rank):
        return f"Model columns: {parts}", []
    full = rank >= columns
    text = f"Rank <b>{rank} of {columns}</b> model columns: {parts}" + (
        "; every column is excited" if full else "; the data leave columns unexcited"
    )
    return text, [] if full else ["poor"]


def _certainty_fact(doc: dict) -> tuple[str, list[str]]:
    coefs = [c for c in doc.get("coefficients") or [] if c.get("kept", True)]
    stds = [(c.get("std_percent"), c) for c in coefs if is_number(c.get("std_percent"))]
    if not stds:
        return "", []
    worst = sorted(stds, key=lambda x: -x[0])[:3]
    within = sum(1 for s, _ in stds if s <= UNCERTAIN_PERCENT)
    names = ", ".join(
        f"{esc(c.get('name'))} ({esc(_short(c.get('expression', '')))}) &plusmn;{number(s, 3)} %"
        for s, c in worst
    )
    text = (
        f"{within} of {len(stds)} coefficients known to &plusmn;{UNCERTAIN_PERCENT:g} % "
        f"(1 std); worst identified: {names}"
    )
    return text, []


def _short(expression: str, n: int = 28) -> str:
    return expression if len(expression) <= n else expression[: n - 3] + "..."


def used_structure(doc: Any) -> str | None:
    """The structure the identified model holds (``metadata.terms``, its name as the
    candidates are named: ``"links + viscous + coulomb - fc5"``), which the one-step
    consistent fit uses too; None when the record does not say."""
    terms = _get(doc, "metadata", "terms")
    if not isinstance(terms, list) or not all(isinstance(t, str) for t in terms):
        return None
    try:
        return Structure.parse(",".join(terms) or "links").name
    except DynidError:
        return None


def _gravity_facts(doc: dict) -> list[str]:
    """The fact (HTML) of a gravity vector fitted for a tilted base (``gravity_fitted``):
    the angles [deg], both held-out errors [%] and the vector the model holds; none
    without one."""
    rec = _get(doc, "metadata", "gravity_fitted")
    if not isinstance(rec, dict):
        return []
    try:
        ax, ay = (float(a) for a in rec["angle_deg"])
        level, fitted = float(rec["level_percent"]), float(rec["fitted_percent"])
        g = ", ".join(f"{float(x):.6g}" for x in rec["gravity"])
    except (KeyError, TypeError, ValueError):
        return []
    return [
        f"<b>Gravity fitted: the base reads tilted {ax:.2f} deg about x and {ay:.2f} deg "
        f"about y</b> (held-out error {level:.3g} % with the description's level gravity, "
        f"{fitted:.3g} % with the fitted one); the model holds gravity = [{esc(g)}] m/s^2 "
        "in the base frame, and validate, observe and the exports use it"
    ]


def _terms_fact(doc: dict) -> str:
    sel = _selection(doc)
    used = used_structure(doc)
    if isinstance(sel, dict) and sel.get("chosen") and used not in (None, sel["chosen"]):
        return (
            f"Terms used: <b>{esc(used)}</b> (the model's, and a consistent fit's); the "
            f"structure chosen on held-out data was {esc(sel['chosen'])} by "
            f"{esc(sel.get('rule', 'held-out error'))}"
        )
    if isinstance(sel, dict) and sel.get("chosen"):
        chosen = [c for c in sel.get("candidates") or [] if c.get("name") == sel["chosen"]]
        listed = ", ".join(chosen[0].get("terms") or []) if chosen else ""
        return (
            f"Terms chosen: <b>{esc(sel['chosen'])}</b>"
            + (f" ({esc(listed)})" if listed else "")
            + f" by {esc(sel.get('rule', 'held-out error'))}"
        )
    terms = [f"rigid body ({len(doc.get('coefficients') or [])} base parameters)"]
    fixed = _get(doc, "metadata", "terms")
    if isinstance(fixed, list):  # given with --terms
        return "Terms given: " + esc(" + ".join(["links", *map(str, fixed)]))
    appended = doc.get("terms")
    if isinstance(appended, list) and appended:
        terms += [str(t.get("name")) for t in appended if isinstance(t, dict)]
    else:
        if _get(doc, "metadata", "friction_labels"):
            terms.append("classical friction fv, fc, fo per joint")
        if doc.get("drive"):
            terms.append("drive train (rotor inertia)")
    return "Terms: " + esc(" + ".join(terms))


def answer(run: RunFiles) -> Answer | None:
    """The identify page's verdict and parts, or None without identification.json."""
    doc = run.docs.get("identification.json")  # the run's own, not a stage folder's
    if not isinstance(doc, dict):
        return None
    held = run.doc("heldout.json")
    if doc.get("route") == "static":
        facts, problems, headline = _static_facts(doc)
    else:
        consistent = _consistent_heldout(run)
        contradicted = any(k in w for w in run.summary.warnings for k in _DATA_WARNINGS)
        facts, problems, headline = _heldout_facts(
            doc, held, contradicted, floor_fact=consistent is None
        )
        if consistent is not None:  # the answer asked for: the consistent fit's error
            first, more, headline = _consistent_facts(doc, consistent)
            above = _above_noise(held) if isinstance(held, dict) else ""
            headline += f"; least squares leaves {esc(above)}" if above else ""
            own = "Held-out error of least squares"  # says whose already
            facts = first + [
                f if f.startswith(own) else f"Least squares: {f[0].lower()}{f[1:]}" for f in facts
            ]
            problems = more + problems
        facts += spring_facts(held)  # where the verdict names a spring: its stiffness
        facts += finding_facts(doc)  # what the record found of the data (.identify_findings)
        facts[:0] = delay_facts(doc)  # a named lag first: the hints after it may be the lag
        facts[:0] = _gravity_facts(doc)  # the gravity every number above was fitted with
        facts[:0] = cut_facts(doc)  # data the fit left out of a recording: beside the verdict
    rank, p = _rank_fact(doc)
    facts.append(rank)
    problems += p
    certainty, _ = _certainty_fact(doc)
    facts += [certainty] if certainty else []
    facts.append(_terms_fact(doc))
    facts += _warning_facts(run, problems)
    level = worst(*problems)  # type: ignore[arg-type]
    label = None
    if level == "good" and re.search(r"at the (sensor-)?noise floor", headline):
        label = "at the noise floor"
    if not headline:
        headline = "The identification's record holds no error to judge it by"
        level = "fair"
    shown = frozenset(f for f, _ in FIGURES if f in run.files)
    sections = [_torques_section(run, held), delay_section(doc), springs_section(held)]
    sections.append(_structure_section(doc))
    sections.append(offsets_section(doc))
    if isinstance(held, dict):  # a --validate-on log outside the training's motion
        sections.append(outside_section(held, [str(x) for x in held.get("joint_names") or ()]))
    sections += [_coefficients_section(doc), *terms_sections(doc)]
    return Answer(
        verdict(level, esc(headline) + ".", facts, label),
        tuple(s for s in sections if s),
        shown,
    )


#: Warnings that say the data contradict the model whatever its errors: the verdict is
#: unusable (check the data before the model).
#: Warnings that say the data contradict the robot: torques of the opposite sign,
#: positions in degrees, torques 30 or more times off its gravity torques (a torque
#: constant or unit a power of ten off: the masses fitted are off by as much).
_DATA_WARNINGS = ("anti-correlated", "look like degrees", "times the model's gravity torques")


def cut_facts(doc: dict) -> list[str]:
    """One fact per recording the fit cut spans out of (``metadata.recordings[].cut_out``):
    which recording, which span and why (outlying among the recordings,
    ``metadata.selection.outlying_recordings``, or a burst in the fit's own residual): the
    cut changes the data the model was fitted on, so it is said beside the verdict, not
    only among the warnings."""
    recs = _get(doc, "metadata", "recordings") or ()
    odd = set(_get(doc, "metadata", "selection", "outlying_recordings") or ())
    odd |= set(_get(doc, "metadata", "outlying_recordings") or ())
    out = []
    for r in recs:
        if not isinstance(r, dict) or not r.get("cut_out"):
            continue
        spans = ", ".join(
            f"t = {a:.4g} to {b:.4g} s" for a, b in r["cut_out"] if is_number(a) and is_number(b)
        )
        n = r.get("cut_samples")
        held = f" ({n} recorded samples)" if isinstance(n, int) else ""
        why = (
            "its held-out error there far above the other recordings'"
            if r.get("file") in odd
            else "a burst in the fit's own residual (a contact or a logging fault, not the model)"
        )
        out.append(
            f"<b>Cut out of the fit</b>: {esc(str(r.get('file', 'a recording')))}, "
            f"{esc(spans)}{held}: {esc(why)}; --keep-outlying fits it whole"
        )
    return out


def _warning_facts(run: RunFiles, problems: list[str]) -> list[str]:
    """Facts (and an unusable verdict in ``problems``) from the run's warnings: torques of the
    opposite sign or positions in degrees fit as well as the right ones, and a model fitted
    to them predicts the robot's torques wrongly (200 % on a correctly signed log)."""
    bad = [w for w in run.summary.warnings if any(k in w for k in _DATA_WARNINGS)]
    if not bad:
        return []
    problems.append("unusable")
    return [f"<b>The data contradict the robot</b>: {esc(w)}" for w in bad]


def _torques_section(run: RunFiles, held: dict | None) -> str:
    figs = [figure(f, run.files[f], caption) for f, caption in FIGURES if f in run.files]
    parts = [f'<div class="figures">{"".join(figs)}</div>'] if figs else []
    if held is not None and isinstance(held.get("rms"), list):
        names = held.get("joint_names") or [f"joint {j + 1}" for j in range(len(held["rms"]))]
        noise = held.get("noise_rms") or [None] * len(names)
        sensor = held.get("sensor_noise_rms") or noise  # an older file: the sensors' alone
        states = held.get("input_noise_rms")  # the held-out states' noise through the model
        folds = held.get("fit_noise_rms")  # the folds' own coefficients' (each recording's)
        rel = held.get("relative_error_percent_per_joint") or [None] * len(names)
        rows = []
        weighed = held.get("joint_ratios")  # the verdict's, each sample against its noise
        weighed = weighed if isinstance(weighed, list) and len(weighed) == len(names) else None
        for j, name in enumerate(names):
            e, s = held["rms"][j], noise[j] if j < len(noise) else None
            ratio = e / s if is_number(e) and is_number(s) and s > 0 else None
            ratio = weighed[j] if weighed is not None and is_number(weighed[j]) else ratio
            row = [esc(name), cell(e), cell(sensor[j] if j < len(sensor) else None)]
            row += [cell(states[j] if j < len(states) else None)] if states else []
            row += [cell(folds[j] if j < len(folds) else None)] if folds else []
            rows.append([*row, cell(ratio), cell(rel[j])])
        headers = [
            "joint",
            f"held-out RMS error [{(u := file_unit(held, 'rms'))}]",
            f"sensor noise RMS [{u}]",
            *([f"states' noise through the model RMS [{u}]"] if states else []),
            *([f"noise of the coefficients fitted without them RMS [{u}]"] if folds else []),
            "error / noise" + (" (each sample against its own)" if weighed else ""),
            "held-out relative error [%]",
        ]
        said = (
            f"{held.get('block', 'Held-out data')}: {verdict_samples(held)} (the verdict's numbers)"
        )
        parts.append(f"<p>{esc(capitalised(said))}.</p>" + table(headers, rows))
    if not parts:
        return ""
    return section("torques", "Torques on held-out data", *parts)


def _selection(doc: dict) -> Any:
    """The model structure chosen on held-out data (``metadata.selection``), or None."""
    return _get(doc, "metadata", "selection")


def _structure_section(doc: dict) -> str:
    sel = _selection(doc)
    if not isinstance(sel, dict) or not sel.get("candidates"):
        return _given_section(doc)
    chosen = sel.get("chosen")
    rows, marked = [], []

    def why(c: dict) -> str:
        if c.get("not_dissipative"):
            return "skipped: not dissipative"
        return "skipped: Stribeck bump below zero" if c.get("negative_bump") else ""

    skip = not all(why(c) for c in sel["candidates"])
    left = any(c.get("left_out") for c in sel["candidates"])
    for c in sel["candidates"]:
        mark = c.get("name") == chosen
        skipped = why(c) if skip else ""
        rows.append(
            [
                "&#10003; chosen" if mark else skipped,
                esc(c.get("name", "")),
                cell(c.get("terms") or []),
                cell(c.get("n_params")),
                cell(c.get("train_error_percent")),
                cell(c.get("heldout_error_percent")),
                cell(c.get("heldout_se_vs_best_percent", c.get("heldout_se_percent"))),
            ]
            + ([esc(" ".join(c.get("left_out") or ()))] if left else [])
        )
        marked.append(mark)
    headers = [
        "",
        "candidate",
        "terms",
        "parameters",
        "training error [%]",
        "held-out error [%]",
        "std. error of the difference from the best [%]",
    ] + (["left out per joint"] if left else [])
    rule = f"Rule: {esc(sel.get('rule', ''))}; validation: {esc(sel.get('validation', ''))}."
    kept = determined_sentence(sel.get("kept_determined"))
    rule += "" if kept is None else f" {esc(capitalised(kept))}."
    if own := sel.get("heldout_own_offsets"):  # the recordings' offsets fitted one each
        rule += (
            " The held-out errors hold each held-out recording's own torque offset on "
            f"{len(own)} joint(s) (fitted one per recording); a new recording's offset is "
            "unknown to the model, its error higher."
        )
    parts = [f"<p>{rule}</p>", table(headers, rows, marked=marked)]
    per = _per_recording_table(doc, sel, "chosen structure", judged=True)
    if per:
        parts.append(per)
        differ = tuple(
            f"{d.get('file')}: held-out error"
            for d in sel.get("differing_recordings") or ()
            if isinstance(d, dict)
        )
        said = [
            n
            for n in sel.get("notes") or ()
            if str(n).startswith(DISAGREE_NOTE) or (differ and str(n).startswith(differ))
        ]
        parts += [f"<p>{esc(capitalised(str(n)))}.</p>" for n in said]
    return section("structure", "Model structure", *parts)


def _given_section(doc: dict) -> str:
    """A structure given (``--terms``) over several recordings: its held-out error per
    recording (``metadata.heldout_per_recording``), those outlying marked; empty without."""
    meta = _get(doc, "metadata")
    per = _per_recording_table(doc, meta, "structure given") if isinstance(meta, dict) else ""
    if not per:
        return ""
    terms = ", ".join(str(t) for t in meta.get("terms") or ()) or "links"
    return section("structure", "Model structure", f"<p>Structure given: {esc(terms)}.</p>", per)


def _per_recording_table(doc: dict, record: dict, what: str, judged: bool = False) -> str:
    """The table of the ``what`` structure's held-out error per recording (``record``'s
    ``heldout_per_recording``), those outlying (``outlying_recordings``) said left out of
    the fit or fitted, as ``doc``'s ``recordings`` mark them (``judged``: and left out of
    the structure's judgement); empty without."""
    per = [r for r in record.get("heldout_per_recording") or () if isinstance(r, dict)]
    if not per:
        return ""
    odd = set(record.get("outlying_recordings") or ())
    differ = {
        d.get("file") for d in record.get("differing_recordings") or () if isinstance(d, dict)
    }
    recs = _get(doc, "metadata", "recordings") or ()
    out = {r.get("file") for r in recs if isinstance(r, dict) and r.get("left_out")}
    cut = {r.get("file") for r in recs if isinstance(r, dict) and r.get("cut_out")}

    def said(name: Any) -> str:
        if name in differ:
            return "clearly above the others' (not outlying): fitted, named in a note"
        if name not in odd:
            return ""
        if name in cut:
            return "outlying: its spans cut out of the fit, the rest fitted"
        if name in out:
            return f"outlying: left out of {'the judgement and of ' if judged else ''}the fit"
        return (
            f"outlying: {'left out of the judgement, ' if judged else ''}fitted (--keep-outlying)"
        )

    rows = [
        [esc(r.get("file", "")), cell(r.get("heldout_error_percent"))]
        + ([said(r.get("file"))] if odd or differ else [])
        for r in per
    ]
    head = ["recording", "held-out error [%]"] + (["judgement"] if odd or differ else [])
    return f"<p>Held-out error of the {what} per recording (fitted on the others).</p>" + table(
        head, rows
    )


def _coefficients_section(doc: dict) -> str:
    """The base parameters as ``coefficients[]`` holds them, each with its std as a bar;
    where the file compares them with the description's (``vs_description``), its value
    of each and ``z``, with the summary's line above the table."""
    coefs = doc.get("coefficients") or []
    if not coefs:
        return ""
    top = max([c.get("std_percent", 0) for c in coefs if is_number(c.get("std_percent"))] + [100])
    vs = doc.get("vs_description")
    described = isinstance(vs, dict)
    rows = []
    for k, c in enumerate(coefs):
        s = c.get("std_percent")
        rows.append(
            [
                str(k + 1),
                esc(c.get("name", "")),
                f'<span class="expr">{esc(c.get("expression", ""))}</span>',
                cell(c.get("value")),
                cell(c.get("std")),
                esc(coefficient_unit(c.get("expression", ""))),
                cell(s),
                bar(s, top, log=True, bad=UNCERTAIN_PERCENT) if is_number(s) else "",
                *([cell(c.get("description")), cell(c.get("z"))] if described else []),
                cell(c.get("kept")),
            ]
        )
    headers = [
        "#",
        "coefficient",
        "expression (standard parameters)",
        "value",
        "std",
        "unit",
        "std [%]",
        f"std [%], log scale (red above {UNCERTAIN_PERCENT:g} %)",
        *(["description's value", "z [std]"] if described else []),
        "kept",
    ]
    said = ""
    if isinstance(vs, dict) and isinstance(vs.get("said"), str):
        said = (
            f"<p>The identified values {esc(vs['said'])}; z = (value - description's "
            "value) / std.</p>"
        )
    return section(
        "coefficients",
        "Coefficients and their standard deviations",
        said,
        table(headers, rows, cls="coefficients"),
    )
