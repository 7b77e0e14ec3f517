"""JSON results as tables: what a report shows of every file a run wrote.

Scalars become a key/value table (with the file's ``units``), records such as
``coefficients[]`` or ``joints[]`` rows, per-joint vectors side by side named by the joint
names, small matrices a table; larger arrays are named with their shape and left in the
file. :func:`key_numbers` finds the results a page without a command's own answer shows
first.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

from .._times import stamp_text
from .html import (
    MAX_VECTOR,
    cell,
    esc,
    href,
    is_matrix,
    is_number,
    is_records,
    is_scalar,
    is_string_list,
    is_vector,
    number,
    table,
)

__all__ = ["json_section", "key_numbers", "names_for"]

#: Records (rows) of one JSON list shown in a table; the rest stay in the file.
MAX_ROWS = 80
#: Largest matrix shown as a table (rows, columns); larger arrays are named by shape.
MAX_MATRIX = (12, 12)
#: Nesting of JSON objects shown (deeper ones are named and left in the file).
MAX_DEPTH = 3
#: Tables of more rows than this start collapsed.
LONG_TABLE = 50

#: Results shown first, found by key at the top of a JSON file or one object down:
#: (key, label).
KEY_NUMBERS = (
    ("feasible", "feasible"),
    ("relative_error_percent", "relative error [%]"),
    ("rank", "rank"),
    ("condition_number", "condition number"),
    ("residual_rms", "residual RMS"),
    ("sigma", "noise estimate"),
    ("relative_residual", "relative residual"),
    ("residual_ratio", "residual ratio"),
    ("mass", "mass [kg]"),
    ("constraint_active", "constraint active"),
    ("status", "status"),
    ("n_samples", "samples"),
)

#: Columns of JSON records (``joints[]``) whose largest value is a key number: (key, label).
KEY_COLUMNS = (("rms_before", "RMS before"), ("rms_after", "RMS after"))


def _with_unit(key: str, units: Mapping[str, str]) -> str:
    """``key [unit]`` when ``units`` gives a short unit for ``key``."""
    unit = units.get(key)
    if isinstance(unit, str) and unit and len(unit) <= 14:
        return f"{key} [{unit}]"
    return key


#: Keys of a time stamp [s] (a start, an end: not a duration), printed to the millisecond
#: (:func:`~dynid._times.stamp_text`): four significant digits leave ``1.765e+09`` of a
#: stamp on the epoch's clock, which names no sample.
STAMP_KEYS = frozenset({"start", "end", "start_s", "end_s"})


def _stamp_cell(key: str, v: Any, units: Mapping[str, str]) -> str:
    """``v`` as a cell; a number at a time stamp's key (:data:`STAMP_KEYS`, in seconds: its
    unit ``s`` or its name) to the millisecond, as the log holds it."""
    in_s = units.get(key) == "s" or key.endswith("_s")
    if key in STAMP_KEYS and in_s and is_number(v) and math.isfinite(v):
        return f'<span class="n">{stamp_text(v)}</span>'
    return cell(v)


def names_for(n: int, labels: Sequence[list[str]]) -> list[str]:
    """The first of ``labels`` (joint names, link names) with ``n`` entries, else 1..n."""
    return next((names for names in labels if len(names) == n), [str(i + 1) for i in range(n)])


def _name_header(n: int, labels: Sequence[list[str]]) -> str:
    """The header over the row names: ``name`` (joint or link names), else ``#``."""
    return "name" if any(len(names) == n for names in labels) else "#"


def _records_table(
    key: str, records: list[dict], units: Mapping[str, str], labels: Sequence[list[str]] = ()
) -> str:
    """Records (``joints[]``) as a table, one row each; rows without a name of their own
    are named by ``labels`` (the joint names, when as many) or numbered. A long table
    starts collapsed."""
    columns: list[str] = []
    for r in records:
        columns += [k for k in r if k not in columns]
    shown = records[:MAX_ROWS]
    rows = [[_stamp_cell(c, r.get(c), units) for c in columns] for r in shown]
    headers = [_with_unit(c, units) for c in columns]
    if not {"name", "link", "joint", "method"} & set(columns):
        names = names_for(len(records), labels)
        headers.insert(0, _name_header(len(records), labels))
        for i, row in enumerate(rows):
            row.insert(0, esc(names[i]))
    more = len(records) - len(shown)
    tail = f'<p class="dim">{more} more rows in the file.</p>' if more > 0 else ""
    body = table(headers, rows) + tail
    if len(records) > LONG_TABLE:
        return f"<details><summary>{esc(key)} ({len(records)} rows)</summary>{body}</details>"
    return f"<h4>{esc(key)}</h4>" + body


def _vectors_table(
    vectors: dict[str, list], labels: Sequence[list[str]], units: Mapping[str, str]
) -> str:
    """Same-length numeric vectors side by side, one row per element (joint, link)."""
    n = len(next(iter(vectors.values())))
    names = names_for(n, labels)
    rows = [[esc(names[i])] + [number(v[i]) for v in vectors.values()] for i in range(n)]
    return table([_name_header(n, labels), *(_with_unit(k, units) for k in vectors)], rows)


#: Names of the columns of the matrices JSON results hold, by key (with their units).
MATRIX_COLUMNS = {"friction": ("fv [N m s/rad]", "fc [N m]", "fo [N m]")}


def _matrix_table(key: str, m: list[list], labels: Sequence[list[str]] = ()) -> str:
    names = names_for(len(m), labels)
    rows = [[esc(names[i])] + [number(x) for x in r] for i, r in enumerate(m)]
    known = MATRIX_COLUMNS.get(key, ())
    columns = known if len(known) == len(m[0]) else [f"column {j + 1}" for j in range(len(m[0]))]
    headers = [_name_header(len(m), labels), *columns]
    return f"<h4>{esc(key)}</h4>" + table(headers, rows, cls="matrix")


def _object_html(
    doc: Mapping[str, Any],
    depth: int,
    labels: Sequence[list[str]] = (),
    units: Mapping[str, str] | None = None,
) -> str:
    """A JSON object: its scalars as a key/value table, then its vectors, records,
    matrices and nested objects (nested objects in collapsible blocks). ``labels`` name
    the rows of per-joint vectors (``joint_names``, or ``joints`` when it lists names as in
    ``thresholds.json``); ``units`` (the file's ``units``) give units to keys."""
    own = [doc[k] for k in ("joint_names", "link_names") if is_string_list(doc.get(k))]
    labels = [*own, *labels]
    # a ``joints`` list of names names per-joint vectors, not records (events.json's events)
    named = [doc["joints"]] if is_string_list(doc.get("joints")) else []
    vector_labels = [*own, *named, *labels[len(own) :]]
    own_units = doc.get("units") if isinstance(doc.get("units"), dict) else None
    units = own_units or units or {}
    scalars, vectors, records, matrices, objects, other = [], {}, [], [], [], []
    for key, v in doc.items():
        if key == "schema":
            continue
        if is_scalar(v) or (isinstance(v, list) and not v):
            scalars.append((key, v))
        elif is_vector(v):
            vectors[key] = v
        elif is_records(v):
            records.append((key, v))
        elif is_matrix(v) and len(v) <= MAX_MATRIX[0] and len(v[0]) <= MAX_MATRIX[1]:
            matrices.append((key, v))
        elif isinstance(v, dict):
            objects.append((key, v))
        else:
            other.append((key, v))
    parts = []
    by_length: dict[int, dict[str, list]] = {}
    for key, v in vectors.items():
        by_length.setdefault(len(v), {})[key] = v
    for group in by_length.values():
        n = len(next(iter(group.values())))
        if not _has_names(n, vector_labels) and (n <= 3 or (len(group) == 1 and n <= MAX_VECTOR)):
            scalars += list(group.items())  # xyz, a few values: inline
        elif len(next(iter(group.values()))) <= MAX_ROWS:
            parts.append(_vectors_table(group, vector_labels, units))
        else:
            other += list(group.items())
    rows = [[esc(k), _stamp_cell(k, v, units), esc(units.get(k, ""))] for k, v in scalars + other]
    if rows:
        with_units = any(r[2] for r in rows)
        headers = ["key", "value", "unit"] if with_units else ["key", "value"]
        parts.insert(0, table(headers, [r if with_units else r[:2] for r in rows], cls="kv"))
    parts += [_records_table(k, v, units, labels) for k, v in records]
    parts += [_matrix_table(k, v, vector_labels) for k, v in matrices]
    for key, v in objects:
        if depth >= MAX_DEPTH:
            parts.append(f'<p class="dim">{esc(key)}: {len(v)} entries (in the file)</p>')
            continue
        inner = (
            _object_html(v, depth + 1, vector_labels, units) if v else '<p class="dim">empty</p>'
        )
        parts.append(f"<details><summary>{esc(key)}</summary>{inner}</details>")
    return "".join(parts)


def _units(doc: Mapping[str, Any]) -> Mapping[str, str]:
    """The ``units`` of a JSON result (key -> unit), or none."""
    units = doc.get("units")
    return units if isinstance(units, dict) else {}


def _has_names(n: int, labels: Sequence[list[str]]) -> bool:
    return any(len(names) == n for names in labels)


def json_section(rel: str, doc: Any, *, collapsed: bool = False) -> str:
    """A JSON file as tables under its linked name (folded away with ``collapsed``)."""
    schema = doc.get("schema") if isinstance(doc, dict) else None
    tag = f' <span class="schema">{esc(schema)}</span>' if isinstance(schema, str) else ""
    head = f'<h3><a href="{href(rel)}">{esc(rel)}</a>{tag}</h3>'
    if isinstance(doc, dict):
        body = _object_html(doc, 1)
    elif is_records(doc):
        body = _records_table(rel, doc, {})
    elif doc is None:
        body = '<p class="dim">not readable as JSON; see the file</p>'
    else:
        body = f"<p>{cell(doc)}</p>"
    if collapsed:
        return (
            f'<section class="result"><details><summary>{esc(rel)}{tag}</summary>'
            f'<p><a href="{href(rel)}">{esc(rel)}</a></p>{body}</details></section>'
        )
    return f'<section class="result">{head}{body}</section>'


def key_numbers(docs: Sequence[tuple[str, Any]]) -> list[tuple[str, str, Any]]:
    """(file, label, value) of the :data:`KEY_NUMBERS` found in the JSON results, at the
    top of each file or one result object down (``with_friction``); a number another
    file already showed is not repeated."""
    found, seen = [], set()
    for rel, doc in docs:
        if not isinstance(doc, dict):
            continue
        places = [("", doc)] + [
            (f"{k.replace('_', ' ')}: ", v)
            for k, v in doc.items()
            if isinstance(v, dict)
            and k not in _NOT_RESULTS
            and sum(key in v for key, _ in KEY_NUMBERS) >= 2
        ]
        for prefix, obj in places:
            for key, label in KEY_NUMBERS:
                v = obj.get(key)
                if not is_scalar(v) or v is None or (key, cell(v)) in seen:
                    continue
                seen.add((key, cell(v)))
                found.append((rel, prefix + label, v))
        for key, records in doc.items():
            if not is_records(records):
                continue
            for column, label in KEY_COLUMNS:
                values = [r.get(column) for r in records]
                if values and all(is_number(x) for x in values):
                    unit = _with_unit(column, _units(doc))[len(column) :]
                    text = f"{label}{unit}, largest of {len(values)} {key}"
                    found.append((rel, text, max(values)))
    return found


#: Objects of a JSON result that describe rather than result (not searched for key numbers).
_NOT_RESULTS = frozenset(
    {"units", "conventions", "base", "metadata", "robot", "kinematics", "options", "bounds", "std"}
)
