"""What a torque log's header holds when a signal's columns are missing: the columns it
does not use, and the ``--columns`` map that would read them.

Other tools name a joint signal's columns their own way: ROS ``sensor_msgs/JointState``
(``position``, ``velocity``, ``effort``), a vendor's ``torque``. Such a family, one column
per joint numbered ``1..n`` (``{i}``) or ``0..n-1`` (``{i0}``), is offered as the map that
reads it (``--columns 'tau=effort{i}'``), never read by itself: a JointState's ``effort``
is whatever its driver puts there, a joint torque on one arm and a motor current on
another, and a wrong column silently read is a wrong answer.

The joint's number may stand inside the name, a word for the joint before it and the
signal's after (a vendor API's ``joint_0_position_deg``: ``joint_{i0}_position_deg``), and
a unit may end it (``_deg``, ``_degps``, ``_Nm``, ``_A``, ``_mNm``): the units other than
SI are offered with the map (``--units 'q=deg,dq=deg/s'``, :data:`UNIT_WORDS`).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence

__all__ = [
    "ALIASES",
    "CURRENT_ALIASES",
    "COMMANDED_WORDS",
    "JOINT_WORDS",
    "UNIT_WORDS",
    "column_hint",
    "commanded_torques",
    "guessed_map",
    "holdings",
    "joint_families",
    "missing_joints",
    "no_torques",
    "position_count",
    "static_map",
    "time_column",
]

#: Names other tools give a torque log's joint signals (lower case, without separators),
#: by dynid's name of the signal.
ALIASES: dict[str, tuple[str, ...]] = {
    "q": ("position", "pos", "jointposition", "jointpos", "angle", "jointangle", "q"),
    "dq": ("velocity", "vel", "jointvelocity", "jointvel", "qd", "qdot", "dq"),
    "tau": (
        "effort",
        "eff",
        "torque",
        "trq",
        "jointtorque",
        "jointeffort",
        "tau",
        "taumeasured",
        "tauj",
    ),
}
#: Names of motor currents' columns (lower case, without separators): read as ``tau`` in
#: amperes (``--units tau=A``) through a drive whose effort is current.
CURRENT_ALIASES = ("current", "cur", "i", "motorcurrent", "amps")
#: Prefixes of a reading's name that say which value it is, not what (a servo's
#: ``present_position_1``, a controller's ``actual_torque_1``), left out before the names
#: are compared with :data:`ALIASES` (lower case, without separators; longest first).
READING_PREFIXES = ("measured", "feedback", "present", "actual", "meas", "act", "fb")
#: Words of a column's name that say it holds what a controller asked for or its model
#: computed, not what was measured (lower case; a word between separators or at a case
#: change: a UR's ``target_moment_0``, libfranka's ``tau_J_d``, ``effort_desired``,
#: ``torque_cmd``); ``d`` counts only after the first word (``tau_d``, not ``d_tau``).
COMMANDED_WORDS = (
    "target",
    "desired",
    "des",
    "d",
    "cmd",
    "command",
    "commanded",
    "setpoint",
    "ref",
    "reference",
    "demand",
    "model",
    "feedforward",
    "ff",
)
#: How many unused columns a message names (families count as one).
SHOWN = 6
#: Words naming the joint before its number inside a column's name (``joint_0_position``),
#: left out before the names are compared with :data:`ALIASES`.
JOINT_WORDS = ("joint", "jnt", "j", "axis", "actuator")
#: A unit ending a column's name (lower case, without separators), by signal: its
#: ``--units`` entry (``None``: SI, nothing to say). A unit of another signal than the one
#: the name reads as is left alone.
UNIT_WORDS: dict[str, dict[str, str | None]] = {
    "q": {"deg": "deg", "degrees": "deg", "rad": None},
    "dq": {
        "degps": "deg/s",
        "degs": "deg/s",
        "degpersec": "deg/s",
        "dps": "deg/s",
        "radps": None,
        "rads": None,
    },
    "tau": {"nm": None, "mnm": "mNm", "a": "A", "ma": "mA", "amp": "A"},
}
_ALL_UNITS = frozenset(w for d in UNIT_WORDS.values() for w in d)
#: A column name with the joint's number in it: what comes before, the number, the rest.
_NUMBERED = re.compile(r"(.*?\D)?(\d+)(\D.*)?")


def joint_families(names: Sequence[str], n: int) -> dict[str, list[str]]:
    """The families of one column per joint in ``names``: ``--columns`` template ->
    its columns in joint order (``effort{i}`` -> ``effort1..effortn``, ``effort_{i0}`` ->
    ``effort_0..effort_{n-1}``); only families of exactly ``n`` columns."""
    found: dict[tuple[str, str], dict[int, str]] = {}
    for c in names:
        m = _NUMBERED.fullmatch(c)
        if m is not None:
            key = (m.group(1) or "", m.group(3) or "")
            found.setdefault(key, {})[int(m.group(2))] = c
    out = {}
    for (prefix, suffix), cols in found.items():
        for first, field in ((1, "{i}"), (0, "{i0}")):
            if sorted(cols) == list(range(first, first + n)):
                out[prefix + field + suffix] = [cols[first + j] for j in range(n)]
    return out


def column_hint(
    names: Sequence[str],
    n: int,
    missing: Sequence[str],
    used: set[str],
    optional: Sequence[str] = (),
    *,
    named: int | None = None,
) -> str:
    """``; present but unused: ...; hint: ...`` for a header that lacks the columns of the
    signals ``missing`` (``"tau"``, ``"dq"``) of an ``n``-joint log.

    Parameters
    ----------
    names : sequence of str
        The header.
    n : int
        The joint count (from ``q1..qn``).
    missing : sequence of str
        The signals without their columns, dynid's names.
    used : set of str
        The columns the log reads.
    optional : sequence of str
        Signals the log may lack (the velocities of a positions-only log), mapped too when
        a family of their names is there.
    named : int, optional
        The joints the columns to name count (the chain's, where a servo log holds a
        gripper's column beyond its joints: ``q1..q5`` beside ``position_1..6``); None:
        ``n``.

    Returns
    -------
    str
        The unused columns (:data:`SHOWN` at most, a family as ``effort1..effort7``) and
        the ``--columns`` map of the families whose names are those of :data:`ALIASES`
        for a missing signal (one each; every missing signal found); else how to name or
        map the columns.
    """
    unused = [c for c in names if c not in used and not re.fullmatch(r"tau_ext\d*", c)]
    families = {t: cols for t, cols in joint_families(unused, n).items()}
    in_family = {c for cols in families.values() for c in cols}
    shown = [f"{cols[0]}..{cols[-1]}" for cols in families.values()]
    shown += [c for c in unused if c not in in_family]
    text = ""
    if shown:
        more = len(shown) - SHOWN
        text = f"; present but unused: {', '.join(shown[:SHOWN])}" + (
            f" and {more} more" if more > 0 else ""
        )
    if not missing:
        return text
    found = _found(list(families), (*missing, *optional))
    current = "tau" in found and _root(found["tau"]) in CURRENT_ALIASES
    if all(s in found for s in missing):
        spec = ",".join(f"{s}={found[s]}" for s in ("q", "dq", "tau") if s in found)
        if units := unit_entries(found):
            spec += f"' --units '{','.join(units)}"
        caveat = (
            (
                " with a --drive whose effort is current (motor currents in A)"
                if current
                else " (check that they hold joint torques in N m: motor currents need "
                "--units tau=A and a --drive whose effort is current)"
            )
            if "tau" in found
            else ""
        )
        k = n if named is None else named
        spans = ", ".join(f"{s}1..{s}{k}" for s in ("q", "dq", "tau") if s in found)
        return f"{text}; hint: --columns '{spec}' reads them{caveat}, or name them {spans}"
    k = n if named is None else named
    spans = ", ".join(f"{s}1..{s}{k}" for s in missing)
    return (
        f"{text}; hint: name the columns {spans} (the torque-log format of the docs), or "
        f"map yours with --columns ('tau=effort{{i}}': {{i}} counts joints from 1, {{i0}} "
        "from 0)"
    )


def missing_joints(names: Sequence[str], n_log: int, n: int) -> str:
    """What a header read as a log of ``n_log`` joints lacks for a robot of ``n``: ``missing
    column(s) q2..q7, tau2..tau7 (the file has q1, tau1)``, of each signal whose first
    column is there (``q1``, ``dq1``, ``tau1``), and, when the header holds other columns,
    those and the ``--columns`` map that reads them (:func:`column_hint`); empty when
    ``n_log >= n`` or the header names no such column.

    Parameters
    ----------
    names : sequence of str
        The header.
    n_log : int
        The joints the log was read with (its ``q1..qn``).
    n : int
        The robot's joints.
    """
    if not 0 < n_log < n:
        return ""
    have = set(names)
    signals = [s for s in ("q", "dq", "tau") if f"{s}1" in have]
    gone = {s: [j for j in range(n_log + 1, n + 1) if f"{s}{j}" not in have] for s in signals}
    if not any(gone.values()):
        return ""
    spans = ", ".join(_span(s, js) for s, js in gone.items() if js)
    kept = ", ".join(_span(s, list(range(1, n_log + 1))) for s in signals)
    used = {"t", *(f"{s}{j}" for s in signals for j in range(1, n_log + 1))}
    hint = column_hint(names, n, [s for s in ("q", "tau") if s in signals], used)
    return f"missing column(s) {spans} (the file has {kept}){hint}"


def _span(signal: str, joints: Sequence[int]) -> str:
    """``q2..q7`` (consecutive joints), ``q3`` or ``q2, q5`` (else)."""
    if len(joints) > 1 and list(joints) == list(range(joints[0], joints[-1] + 1)):
        return f"{signal}{joints[0]}..{signal}{joints[-1]}"
    return ", ".join(f"{signal}{j}" for j in joints)


def _found(families: Sequence[str], signals: Sequence[str]) -> dict[str, str]:
    """Signal -> the one family whose name is one of its :data:`ALIASES` (torques: else
    the one family of :data:`CURRENT_ALIASES`); a signal of none or several is left out."""
    found = {}
    for signal in signals:
        for names in (ALIASES.get(signal, ()), CURRENT_ALIASES if signal == "tau" else ()):
            fits = [t for t in families if _root(t) in names]
            if len(fits) == 1:
                found[signal] = fits[0]
                break
    return found


#: Names of static data's families (lower case, without separators), by dynid's name.
STATIC_ALIASES: dict[str, tuple[str, ...]] = {
    "q": ALIASES["q"],
    "g": ("g", "gravity", "grav", "gravitytorque", "gravitytorques"),
    "M": ("m", "mass", "massmatrix", "inertia", "inertiamatrix"),
}


def static_map(names: Sequence[str], n: int, given: Mapping[str, str] | None = None) -> str:
    """The ``--columns`` map that reads static data of header ``names`` for an arm of
    ``n`` joints: ``--columns 'q=q{i0},M=M{k0},g=g{i0}'`` for libfranka's dump (``q0..q6``,
    the mass matrix as one flat column-major array ``M0..M48``, ``g0..g6``); the
    templates ``given`` that name columns of the file kept; empty when ``q``, ``M`` or
    ``g`` cannot be told (none, or several candidates) or the file needs no map.

    ``q`` and ``g`` are families of ``n`` columns numbered ``1..n`` or ``0..n-1``; ``M`` a
    family of ``n * n`` columns numbered ``0..n^2-1`` (``{k0}``) or ``1..n^2`` (``{k}``),
    each of a name of :data:`STATIC_ALIASES` (case and separators aside).
    """
    have = set(names)
    default = {"q": "q{i}", "M": "M{i}_{j}", "g": "g{i}"}

    def present(key: str, tpl: str) -> bool:  # every column of the template there
        if "{" not in tpl:
            return tpl in have
        pairs = [(i, j) for i in range(n) for j in range(i + 1)] if key == "M" else []
        try:
            if key != "M":
                return all(tpl.format(i=i + 1, i0=i) in have for i in range(n))
            return all(
                any(
                    tpl.format(i=a + 1, i0=a, j=b + 1, j0=b, k=a + n * b + 1, k0=a + n * b) in have
                    for a, b in ((i, j), (j, i))
                )
                for i, j in pairs
            )
        except (KeyError, IndexError, ValueError):
            return False

    found = {k: v for k, v in (given or {}).items() if k in default and present(k, v)}
    families = list(joint_families(names, n))
    flat = [t.replace("{i0}", "{k0}").replace("{i}", "{k}") for t in joint_families(names, n * n)]
    for key, candidates in (("q", families), ("g", families), ("M", flat)):
        if key in found or present(key, default[key]):
            continue
        fits = [t for t in candidates if _root(t.replace("{k", "{i")) in STATIC_ALIASES[key]]
        if len(fits) != 1:
            return ""
        found[key] = fits[0]
    if not found or found == dict(given or {}):
        return ""
    return "--columns '" + ",".join(f"{k}={found[k]}" for k in default if k in found) + "'"


def time_column(names: Sequence[str]) -> str | None:
    """The one column of a header whose name reads as time (``time``, ``timestamp``,
    ``time_ms``, ``stamp_s``, ``Time``), or None (none, or several)."""
    found = [
        c
        for c in names
        if re.fullmatch(
            r"(t|time|timestamp|stamp|sec|secs|seconds)([_ ]?(s|ms|us|ns))?", c.strip().lower()
        )
    ]
    return found[0] if len(found) == 1 else None


def guessed_map(names: Sequence[str], given: Mapping[str, str] | None = None) -> str:
    """The options that read a torque log of header ``names``, guessed from it:
    ``--columns 'q=pos{i},tau=eff{i},t=time'`` (and ``--units`` for a time in ms or
    motor currents), keeping the templates ``given`` that name columns of the file; empty
    when the time, the positions or the torques cannot be told (none, or several
    candidates).

    A family is one column per joint numbered ``1..n`` or ``0..n-1`` whose name is one of
    :data:`ALIASES` (``pos``, ``Effort_``; case and separators aside); the time is
    :func:`time_column`.
    """
    given = dict(given or {})
    have = set(names)

    def present(tpl: str) -> bool:
        return (tpl.format(i=1, i0=0) if "{" in tpl else tpl) in have

    cols: dict[str, str] = {k: v for k, v in given.items() if present(v)}
    if "t" not in cols and "t" not in have:
        if (time := time_column(names)) is None:
            return ""
        cols["t"] = time
    n = _count(names, cols.get("q", "q{i}")) or position_count(names)
    if not n:
        return ""
    families = [t for t in joint_families(names, n) if t not in cols.values()]
    default = {"q": "q{i}", "dq": "dq{i}", "tau": "tau{i}"}
    wanted = [s for s in ("q", "dq", "tau") if s not in cols and not present(default[s])]
    cols.update(_found(families, wanted))
    if any(s not in cols and not present(default[s]) for s in ("q", "tau")):
        return ""
    order = [k for k in given if k in cols] + [k for k in ("t", "q", "dq", "tau") if k in cols]
    spec = ",".join(f"{k}={cols[k]}" for k in dict.fromkeys(order))
    units = []
    if "t" in cols and (unit := re.search(r"(ms|us|ns)$", cols["t"].lower())):
        units.append(f"t={unit[1]}")
    units += unit_entries({k: v for k, v in cols.items() if k != "t"})
    return f"--columns '{spec}'" + (f" --units '{','.join(units)}'" if units else "")


def _count(names: Sequence[str], tpl: str) -> int:
    """How many joints' columns ``tpl`` names in ``names`` (from joint 1 on)."""
    if "{" not in tpl:
        return 0
    have, k = set(names), 0
    while tpl.format(i=k + 1, i0=k) in have:
        k += 1
    return k


def holdings(names: Sequence[str]) -> str:
    """A header for a message, each run of numbered columns as one span (``t, q1..q7``)."""
    groups: dict[str, list[int]] = {}
    order: list[tuple[str, bool]] = []  # (name or prefix, whether a prefix)
    for c in names:
        m = re.fullmatch(r"(.*?\D)?(\d+)", c)
        if m is None:
            order.append((c, False))
            continue
        prefix = m.group(1) or ""
        if prefix not in groups:
            order.append((prefix, True))
        groups.setdefault(prefix, []).append(int(m.group(2)))
    spans = []
    for c, numbered in order:
        idx = groups.get(c, []) if numbered else []
        if not numbered:
            spans.append(c)
        elif len(idx) > 2 and idx == list(range(idx[0], idx[0] + len(idx))):
            spans.append(f"{c}{idx[0]}..{c}{idx[-1]}")
        else:
            spans += [f"{c}{i}" for i in idx]
    more = len(spans) - 12
    return ", ".join(spans[:12]) + (f" and {more} more" if more > 0 else "")


def no_torques(names: Sequence[str], n: int, used: set[str]) -> str:
    """What to say of a log of ``n`` joints whose header ``names`` holds no joint torques
    and nothing that could be them (no unused family of ``n`` columns, no column whose
    name has a torque's or current's word in it: ``tau``, ``torq``, ``eff``, ``cur``, ...):
    what the commands reading it need and what the file holds; empty when some column
    might be the torques (then naming or mapping them is the hint)."""
    unused = [c for c in names if c not in used and not re.fullmatch(r"tau_ext\d*", c)]
    like = re.compile(r"tau|torq|trq|eff|cur|amp|nm\b", re.IGNORECASE)  # a unit's name too
    if joint_families(unused, n) or any(like.search(c) for c in unused):
        return ""
    return (
        f"the file holds no joint torques, only {holdings(names)}; identification and the "
        f"observers need measured joint torques (tau1..tau{n} in N m), or motor currents "
        "(--units tau=A with a --drive whose effort is current); hint: record the joint "
        "torques (a JointState's effort, the controller's measured torque) with the positions"
    )


def position_count(names: Sequence[str]) -> int:
    """The joint count of a header without ``q1..qn`` read from a family of positions by
    another name (``position_0..position_6``: 7), 0 when there is none or several."""
    found: dict[tuple[str, str], set[int]] = {}
    for c in names:
        m = _NUMBERED.fullmatch(c)
        if m is None:
            continue
        key = (m.group(1) or "", m.group(3) or "")
        if _root(key[0] + "{i}" + key[1]) in ALIASES["q"]:
            found.setdefault(key, set()).add(int(m.group(2)))
    counts = {len(k) for k in found.values() if k in ({*range(len(k))}, {*range(1, len(k) + 1)})}
    return counts.pop() if len(counts) == 1 else 0


def _name_unit(template: str) -> tuple[str, str]:
    """A family's name without its joint field (before it: a word for the joint left out,
    :data:`JOINT_WORDS`, when a name follows) and its unit's word (:data:`UNIT_WORDS`, the
    last words of the name), lower case without separators: ``joint_{i0}_position_deg``
    -> ``("position", "deg")``, ``position_deg_{i}`` -> ``("position", "deg")``,
    ``effort{i}`` -> ``("effort", "")``."""
    before, _, after = template.partition("{")

    def split(text: str) -> list[str]:
        return [w for w in re.split(r"[^a-z]+", text.lower()) if w]

    head, words = split(before), split(after.partition("}")[2])
    if words and "".join(head) in JOINT_WORDS:
        head = []
    if not words:  # the number ends the name: its unit before it
        head, words = [], head
    unit = ""
    for k in (3, 2, 1):  # deg_per_sec, deg_s, degps
        if len(words) > k and "".join(words[-k:]) in _ALL_UNITS:
            unit, words = "".join(words[-k:]), words[:-k]
            break
    return "".join(head + words), unit


def unit_entries(found: Mapping[str, str]) -> list[str]:
    """The ``--units`` entries the unit words ending the families ``found`` (signal ->
    template) say, in signal order: ``["q=deg", "dq=deg/s"]`` for
    ``joint_{i0}_position_deg`` and ``joint_{i0}_velocity_degps``; ``tau=A`` for a
    current's family without a unit word."""
    out = []
    for signal in ("q", "dq", "tau"):
        if signal not in found:
            continue
        name, unit = _name_unit(found[signal])
        said = UNIT_WORDS[signal].get(unit)
        if said is None and signal == "tau" and _root(found[signal]) in CURRENT_ALIASES:
            said = "A"  # a current's family without a unit's word
        if said is not None:
            out.append(f"{signal}={said}")
    return out


def _root(template: str) -> str:
    """A family's name without its joint field, separators, a word for the joint, a unit
    (:func:`_name_unit`) and a reading's prefix (:data:`READING_PREFIXES`), lower case
    (``Effort_{i0}`` -> ``effort``, ``present_current_{i}`` -> ``current``,
    ``joint_{i0}_torque_Nm`` -> ``torque``)."""
    root = _name_unit(template)[0]
    for p in READING_PREFIXES:
        if root.startswith(p) and len(root) > len(p):
            return root[len(p) :]
    return root


def _words(template: str) -> list[str]:
    """The words of a column's name or ``--columns`` template, lower case, without its
    joint field and numbers (``target_moment_{i0}`` -> ``target, moment``; ``tauJd`` ->
    ``tau, j, d``)."""
    name = re.sub(r"\{[^}]*\}", " ", template)
    name = re.sub(r"(?<=[a-z0-9])(?=[A-Z])", " ", name)
    return [w for w in re.split(r"[^a-z]+", name.lower()) if w]


def commanded_torques(template: str, names: Sequence[str], n: int) -> str | None:
    """What to warn of torques read from columns whose name says they are commanded,
    desired, a target or a model's (:data:`COMMANDED_WORDS`): a controller's torque holds
    no friction and almost no noise, and a model fitted to it predicts it to a fraction of
    a percent whatever the arm does; None for a name that does not say so.

    Parameters
    ----------
    template : str
        The torques' column template as mapped (``target_moment_{i0}``), or an NPZ
        array's name.
    names : sequence of str
        The file's header: the hint maps a family of measured torques or currents in it
        (:data:`ALIASES`, :data:`CURRENT_ALIASES`) whose name is not a command's.
    n : int
        The joint count.

    Returns
    -------
    str or None
        ``tau is read from target_moment_0..5, a controller's target, not a measurement
        ...; hint: ...``.
    """
    said = _commanded(template)
    if not said:
        return None
    what = {
        "target": "a controller's target",
        "model": "a model's torque",
        "feedforward": "a controller's feed-forward",
        "ff": "a controller's feed-forward",
    }.get(said[0], "a controller's command")
    if "{" in template:
        first, last = template.format(i=1, i0=0), template.format(i=n, i0=n - 1)
        shown = f"{first}..{last.removeprefix(_common_prefix(first, last))}"
    else:
        shown = template
    families = [t for t in joint_families(names, n) if not _commanded(t) and t != template]
    found = _found(families, ("tau",)).get("tau")
    if found is None:
        hint = "map the measured joint torques or motor currents with --columns tau=NAME"
    elif _root(found) in CURRENT_ALIASES:
        hint = f"--columns tau={found} --units tau=A with a --drive whose effort is current"
    else:
        hint = f"--columns tau={found} reads the measured ones"
    return (
        f"tau is read from {shown}, {what}, not a measurement: it may hold no friction "
        "and almost no noise, so a model fitted to it says little of the arm (its error, "
        f"its friction and its verdict); hint: {hint}"
    )


def _commanded(template: str) -> list[str]:
    """The words of a column's name that say it is commanded (:data:`COMMANDED_WORDS`;
    ``d`` after the first word only)."""
    words = _words(template)
    return [w for k, w in enumerate(words) if w in COMMANDED_WORDS and (w != "d" or k > 0)]


def _common_prefix(a: str, b: str) -> str:
    """The longest common prefix of ``a`` and ``b`` not ending in a digit (``q_0``,
    ``q_5``: ``q_``)."""
    k = 0
    while k < min(len(a), len(b)) and a[k] == b[k]:
        k += 1
    return a[:k].rstrip("0123456789")
