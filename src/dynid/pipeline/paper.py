"""The paper's published numbers beside dynid's: what the demo's report sets side by side.

Gaz, Cognetti, Oliva, Robuffo Giordano, De Luca, "Dynamic Identification of the Franka Emika
Panda Robot With Retrieval of Feasible Parameters Using Penalty-Based Optimization", IEEE
RA-L 4(4):4147-4154, 2019:

* Table III (supplementary material): the 43 dynamic coefficients as expressions of the
  standard parameters (``J`` about the link origin, ``c<i><x>*m<i>`` the first moments,
  the constants ``d3, d5, a4, a5, a7`` of the DH table) and their values ``pi(p_hat)``
  printed to 4 decimals (None where the table prints ----). The printed values of
  :data:`TABLE_III_TRANSCRIPTION_ERRORS` disagree with the expressions evaluated at the
  printed ``p_hat`` (a copy error in the table; the other values agree to its rounding).
* The friction (supplementary Table I) and the feasible parameters ``p_hat`` (Tables VIII
  and IX) are those of the built-in robot (:func:`dynid.model.panda.panda`).

:func:`paper_comparison` maps the demo's identified coefficients into the paper's basis
(:func:`~dynid.identification.static.basis_transform`, standard deviations through the
covariance) and sets them, the fitted friction and the retrieved links beside the published
values, each with the difference.
"""

from __future__ import annotations

import ast
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..friction.model import sigmoid_parameters
from ..identification.static import basis_transform
from ..model.robot import Robot
from .demo import DemoResult

__all__ = [
    "TABLE_III",
    "TABLE_III_CONSTANTS",
    "TABLE_III_TRANSCRIPTION_ERRORS",
    "paper_comparison",
    "table_iii_matrix",
]

#: Constants of the expressions of Table III [m].
TABLE_III_CONSTANTS = {"d3": 0.316, "d5": 0.384, "a4": 0.0825, "a5": -0.0825, "a7": 0.088}
#: Indices (1-based) of Table III whose printed value carries a transcription error.
TABLE_III_TRANSCRIPTION_ERRORS = (17, 21, 25, 39)
#: The 43 coefficients of Table III: (expression, printed pi(p_hat) or None).
TABLE_III: tuple[tuple[str, float | None], ...] = (
    ("J2yy + J1zz", 0.0373),
    ("J2xx - J2yy + J3yy + d3^2*m3 + 2*d3*c3z*m3 + (d3^2+a4^2)*(m4+m5+m6+m7)", 0.9896),
    ("J2xy", -0.004),
    ("J2xz", 0.0103),
    ("J2yz", 0.0008),
    ("J3yy + J2zz + d3^2*m3 + 2*d3*c3z*m3 + (d3^2+a4^2)*(m4+m5+m6+m7)", 1.0358),
    ("J3xx - J3yy + J4yy - a4^2*m4", 0.0116),
    ("J3xy + a4*c4z*m4", None),
    ("J3xz", -0.0055),
    ("J3yz", -0.0044),
    ("J4yy + J3zz + a4^2*m4 + (a4^2+a5^2)*(m5+m6+m7)", 0.1245),
    ("J4xx - J4yy + J5yy + 2*d5*c5z*m5 + (d5^2-a5^2)*(m5+m6+m7)", 0.5408),
    ("J4xy - a5*d5*(m5+m6+m7) - a5*c5z*m5", 0.1388),
    ("J4xz", 0.0039),
    ("J4yz", -0.0016),
    ("J5yy + J4zz + (d5^2+a5^2)*(m5+m6+m7) + 2*d5*c5z*m5", 0.6325),
    ("J5xx - J5yy + J6yy + a7^2*m7", -0.0075),
    ("J5xy", -0.0015),
    ("J5xz", -0.0046),
    ("J5yz", 0.0022),
    ("J6yy + J5zz + a7^2*m7", 0.0276),
    ("J6xx - J6yy + J7yy - a7^2*m7", -0.0009),
    ("J6xy + a7*c7z*m7", 0.0055),
    ("J6xz", None),
    ("J6yz", -0.0001),
    ("J7yy + J6zz + a7^2*m7", 0.0304),
    ("J7xx - J7yy", 0.0024),
    ("J7xy", -0.0004),
    ("J7xz", -0.0017),
    ("J7yz", -0.0005),
    ("J7zz", 0.0049),
    ("c2x*m2", -0.002),
    ("c2y*m2 - d3*(m3+m4+m5+m6+m7) - c3z*m3", -3.1043),
    ("a4*(m4+m5+m6+m7) + c3x*m3", 0.6842),
    ("c3y*m3 - c4z*m4", 0.0282),
    ("c4x*m4 + a5*(m5+m6+m7)", -0.4901),
    ("d5*(m5+m6+m7) + c4y*m4 + c5z*m5", 1.7207),
    ("c5x*m5", -0.0147),
    ("c5y*m5 - c6z*m6", 0.0824),
    ("a7*m7 + c6x*m6", 0.165),
    ("c6y*m6 - c7z*m7", -0.0688),
    ("c7x*m7", 0.0077),
    ("c7y*m7", -0.0031),
)


def _linear_form(expression: str, labels: tuple[str, ...]) -> NDArray[np.float64]:
    """The row ``a`` with ``expression = a . phi`` over the standard parameters ``labels``
    (``c<i><x>*m<i>`` read as the first moment ``mc<i><x>``); only sums, products and
    powers of names and numbers are read."""
    index = {name: k for k, name in enumerate(labels)}

    def value(node: ast.AST) -> dict[str, float]:
        # a polynomial as {monomial: coefficient}, monomial "" the constant, else one name
        if isinstance(node, ast.Expression):
            return value(node.body)
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return {"": float(node.value)}
        if isinstance(node, ast.Name):
            if node.id in TABLE_III_CONSTANTS:
                return {"": TABLE_III_CONSTANTS[node.id]}
            return {node.id: 1.0}
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return {k: -v for k, v in value(node.operand).items()}
        if isinstance(node, ast.BinOp):
            a, b = value(node.left), value(node.right)
            if isinstance(node.op, (ast.Add, ast.Sub)):
                sign = 1.0 if isinstance(node.op, ast.Add) else -1.0
                out = dict(a)
                for k, v in b.items():
                    out[k] = out.get(k, 0.0) + sign * v
                return out
            if isinstance(node.op, ast.Mult):
                out = {}
                for ka, va in a.items():
                    for kb, vb in b.items():
                        key = _product(ka, kb)
                        out[key] = out.get(key, 0.0) + va * vb
                return out
            if isinstance(node.op, ast.Pow) and set(a) == {""} and set(b) == {""}:
                return {"": a[""] ** b[""]}
        raise ValueError(f"Table III expression not linear in the parameters: {expression!r}")

    poly = value(ast.parse(expression.replace("^", "**"), mode="eval"))
    row = np.zeros(len(labels))
    for key, coef in poly.items():
        if key == "" and coef == 0.0:
            continue
        row[index[key]] += coef
    return row


def _product(a: str, b: str) -> str:
    """The monomial of two: a constant keeps the other; ``c<i><x>`` times ``m<i>`` is
    ``mc<i><x>``."""
    if not a or not b:
        return a or b
    c, m = (a, b) if a.startswith("c") else (b, a)
    if c.startswith("c") and m == "m" + c[1:-1]:
        return "mc" + c[1:]
    raise ValueError(f"Table III: product of parameters {a} * {b}")


def table_iii_matrix(labels: tuple[str, ...]) -> NDArray[np.float64]:
    """The 43 expressions of Table III as a (43, p) map of the standard parameters
    ``labels`` (``Robot.param_labels``)."""
    return np.array([_linear_form(expr, labels) for expr, _ in TABLE_III])


def _table_iii(demo: DemoResult) -> list[dict[str, Any]]:
    model = demo.identification.model
    T = basis_transform(model.base, table_iii_matrix(tuple(model.base.std_labels)))
    pi = T @ model.beta
    cov = model.fit.covariance
    std = (
        np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", T, np.asarray(cov), T), 0.0))
        if cov is not None
        else np.full(len(pi), np.nan)
    )
    rows = []
    for k, ((expr, printed), value, s) in enumerate(zip(TABLE_III, pi, std, strict=True)):
        diff = None if printed is None else float(value - printed)
        rows.append(
            {
                "index": k + 1,
                "expression": expr,
                "dynid": float(value),
                "dynid_std": float(s) if np.isfinite(s) else None,
                "published": printed,
                "difference": diff,
                "transcription_error": k + 1 in TABLE_III_TRANSCRIPTION_ERRORS,
            }
        )
    return rows


def _friction(demo: DemoResult) -> list[dict[str, Any]]:
    fitted = demo.friction.fit.friction
    published = sigmoid_parameters(demo.robot.friction)
    if published is None or not hasattr(fitted, "phi1"):
        return []
    units = {"phi1": "N m", "phi2": "s/rad", "phi3": "rad/s"}
    rows = []
    for j, joint in enumerate(demo.robot.joint_names):
        for k, name in enumerate(("phi1", "phi2", "phi3")):
            ours = float(getattr(fitted, name)[j])
            rows.append(
                {
                    "joint": joint,
                    "parameter": name,
                    "unit": units[name],
                    "dynid": ours,
                    "published": float(published[j, k]),
                    "difference": ours - float(published[j, k]),
                }
            )
    return rows


def _links(retrieved: Robot, published: Robot) -> list[dict[str, Any]]:
    rows = []
    for k in range(published.n):
        m, m0 = float(retrieved.mass[k]), float(published.mass[k])
        c, c0 = np.asarray(retrieved.com[k]), np.asarray(published.com[k])
        rows.append(
            {
                "link": published.link_names[k + 1],
                "mass": m,
                "mass_published": m0,
                "mass_difference": m - m0,
                "com": c.tolist(),
                "com_published": c0.tolist(),
                "com_distance": float(np.linalg.norm(c - c0)),
            }
        )
    return rows


def _validation(demo: DemoResult) -> list[dict[str, Any]]:
    f = demo.friction
    noise = np.broadcast_to(np.asarray(f.noise.tau_std, dtype=float), (demo.robot.n,))
    return [
        {
            "joint": joint,
            "rms_without_friction": float(f.rms_without_friction[j]),
            "rms_with_friction": float(f.rms_with_friction[j]),
            "sensor_noise": float(noise[j]),
        }
        for j, joint in enumerate(demo.robot.joint_names)
    ]


def paper_comparison(demo: DemoResult) -> dict[str, Any]:
    """dynid's results of the demo beside the paper's published values (JSON-ready).

    Returns
    -------
    dict
        ``table_iii`` (43 rows: expression, dynid's value and std in the paper's basis,
        the printed value, the difference), ``friction`` (per joint and sigmoid parameter),
        ``links`` (retrieved against published masses and centres of mass),
        ``validation`` (per joint RMS without and with friction, and the sensor noise),
        with ``units`` and the ``reference``.
    """
    return {
        "reference": "Gaz et al., IEEE RA-L 4(4):4147-4154, 2019, supplementary Tables I, "
        "III, VIII, IX",
        "table_iii": _table_iii(demo),
        "friction": _friction(demo),
        "links": _links(demo.feasible.retrieval.robot, demo.robot),
        "validation": _validation(demo),
        "units": {
            "table_iii": "SI of each expression: m kg, c*m kg m, J kg m^2",
            "mass": "kg",
            "com": "m, link frame",
            "rms": "N m",
        },
    }
