"""Reports of a solved impact and of a verdict on a candidate u⁺, as plain data and as text.

The command line prints these; ``--json`` prints the data itself. Numbers that are undefined
(e.g. the angle α when there is no impact, docs/theory.md §4) are NaN in the data and ``null`` in
JSON.
"""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from ..laws.catalogue import NAMED_LAWS
from ..laws.result import ImpactResult
from ..model.admissible import AdmissibleSet, Membership
from ..model.problem import ImpactProblem

COEFFICIENT_NAMES = {name: law.coefficient_symbol for name, law in NAMED_LAWS.items()}
KEY_SYMBOLS = {"mu": "μ", "stiffness": "K", "exponent": "η"}
"""How reports print a coefficient of a law of several (Coulomb's μ and e) by its key."""
CONDITIONS = ("kinetic", "kinematic", "energetic")
CONDITION_TEXT = {"kinetic": "u⁺ ∈ u⁻ + N", "kinematic": "u⁺ ∈ T_C",
                  "energetic": "‖u⁺‖ ≤ ‖u⁻‖"}


def jsonable(value: Any) -> Any:
    """Arrays to lists, numpy scalars to Python numbers, NaN/inf to None (strict JSON)."""
    if isinstance(value, dict):
        return {k: jsonable(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    return value


def to_json(report: dict[str, Any]) -> str:
    """Strict JSON text of a report."""
    return json.dumps(jsonable(report), indent=2, allow_nan=False)


def _numbers(value: Any) -> str:
    """A scalar, vector or matrix of coefficients in a short form."""
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        return f"{float(arr):g}"
    if arr.ndim == 1:
        return vector_text(arr)
    return "[" + "; ".join(" ".join(f"{x:g}" for x in row) for row in arr) + "]"


def vector_text(a: Any, digits: int = 6) -> str:
    """A short vector as ``(+1, -0.333333, …)``; long ones are elided in the middle."""
    a = np.asarray(a, dtype=float)
    items = [f"{x:+.{digits}g}" for x in (a if a.size <= 12 else np.r_[a[:5], a[-5:]])]
    if a.size > 12:
        items.insert(5, f"… ({a.size - 10} more) …")
    return "(" + ", ".join(items) + ")"


def membership_report(problem: ImpactProblem, u_plus: np.ndarray, *,
                      optimizer: bool = True, S: AdmissibleSet | None = None) -> dict[str, Any]:
    """The verdict u⁺ ∈ S (docs/theory.md §2): each condition's exact residual, and the optimizer's
    distance.

    The exact test is NNLS plus explicit checks; the optimizer one is the SOCP distance from
    u⁺ to S (:meth:`AdmissibleSet.contains` with ``method="optimizer"``). ``S`` defaults to
    the problem's frictionless S; with friction (docs/theory.md §16) it is
    ``problem.admissible_set(mu=...)``, whose optimizer test is the cone program of the
    kinetic condition (its distance None).
    """
    S = problem.admissible_set() if S is None else S
    exact: Membership = S.contains(u_plus)
    report: dict[str, Any] = {
        "u_plus": u_plus, "admissible": exact.member, "tolerance": exact.tol,
        "conditions": {c: {"residual": exact.residuals[c], "ok": exact.residuals[c] <= exact.tol}
                       for c in CONDITIONS},
        "failed": exact.failed(), "impulses": exact.impulses, "method": exact.method,
    }
    if optimizer:
        opt = S.contains(u_plus, method="optimizer")
        report["optimizer"] = {"distance": opt.distance, "admissible": opt.member,
                               "tolerance": opt.tol}
    return report


def solution_report(result: ImpactResult, source: str = "") -> dict[str, Any]:
    """u⁺, impulses, energies, classification (docs/theory.md §4), admissibility (docs/theory.md
    §2) and certificate."""
    frictional = result.problem.contact_dim > 1
    c = None if frictional else result.classification  # docs/theory.md §4: frictionless
    cert = result.certificate
    S = result.impact_law.admissible_set(result.problem) if result.impact_law else None
    membership = membership_report(result.problem, result.u_plus, optimizer=False, S=S)
    return {
        "source": source, "law": result.law, "coefficients": result.coefficients,
        "backend": result.backend, "u_minus": result.problem.u_minus, "u_plus": result.u_plus,
        "impulses": result.impulses,
        "energy": {"before": result.energy_before, "after": result.energy_after},
        "classification": None if c is None else {
            "alpha_deg": c.alpha_deg, "dissipation": c.dissipation, "intensity": c.intensity},
        "admissibility": {k: v for k, v in membership.items() if k not in ("u_plus", "impulses")},
        "certificate": {"ok": cert.ok, "tolerance": cert.tol, **cert.residuals},
    }


def _conditions_text(report: dict[str, Any]) -> list[str]:
    return [f"  {name:<10} {CONDITION_TEXT[name]:<14} residual {cond['residual']:.1e}  "
            f"{'ok' if cond['ok'] else 'VIOLATED'}"
            for name, cond in report["conditions"].items()]


def format_solution(report: dict[str, Any]) -> str:
    """Plain text of :func:`solution_report`."""
    coef, law = report["coefficients"], report["law"]
    if isinstance(coef, dict):  # the LZB model's stiffness, exponent and restitution
        coef = tuple(coef.values())
    if coef is None:
        coef_text = ""
    elif isinstance(coef, tuple):
        coef_text = "".join(f", {KEY_SYMBOLS.get(key, key)} = {_numbers(value)}" for key, value
                            in zip(NAMED_LAWS[law].coefficient_keys, coef, strict=True))
    else:
        coef_text = f", {COEFFICIENT_NAMES[law]} = {_numbers(coef)}"
    e, c, a = report["energy"], report["classification"], report["admissibility"]
    frictional = c is None  # the classification is of frictionless impacts only
    ratio = e["after"] / e["before"] if e["before"] > 0 else float("nan")
    cert = report["certificate"]
    lines = [
        f"{report['source']}: law {report['law']}{coef_text} (backend {report['backend']})",
        f"u⁻         {vector_text(report['u_minus'])}",
        f"u⁺         {vector_text(report['u_plus'])}",
        f"impulses Λ {vector_text(report['impulses'])}",
        f"energy     before {e['before']:.6g}, after {e['after']:.6g} (ratio {ratio:.6g})",
        *([] if frictional else [
            f"classification: α = {c['alpha_deg']:.4g}°, dissipation ε = "
            f"{c['dissipation']:.4g}, intensity {c['intensity']:.6g}"]),
        f"admissible (u⁺ ∈ S{' with friction' if frictional else ''}): "
        f"{'yes' if a['admissible'] else 'NO'}",
        *_conditions_text(a),
        f"certificate: {'ok' if cert['ok'] else 'FAILED'} (tol {cert['tolerance']:.0e})"
        + "".join(f", {k} {v:.1e}" for k, v in cert.items()
                  if k not in ("ok", "tolerance") and frictional),
    ]
    return "\n".join(lines)


def format_verdict(report: dict[str, Any], source: str = "") -> str:
    """Plain text of :func:`membership_report`."""
    opt = report["optimizer"]
    agree = "" if opt["admissible"] == report["admissible"] else \
        "  (disagrees with the exact test; trust the exact one)"
    if opt["distance"] is None:  # with friction: the cone program of the kinetic condition
        test = "optimizer (cone program for Λ in the friction cones"
        figure = ""
        first = ("exact test (Λ from the impact equation, projected onto the friction cones"
                 if report["method"] == "exact" else
                 "test (Λ not unique: cone program for Λ in the friction cones")
    else:
        test, figure = "optimizer (SOCP distance to S", f"{opt['distance']:.1e}, "
        first = "exact test (NNLS + explicit checks"
    lines = [
        f"{source}: candidate u⁺ = {vector_text(report['u_plus'])}",
        f"{first}, tol {report['tolerance']:.0e}):",
        *_conditions_text(report),
        f"{test}, tol {opt['tolerance']:.0e}): "
        f"{figure}{'in S' if opt['admissible'] else 'not in S'}{agree}",
        f"verdict: {'ADMISSIBLE' if report['admissible'] else 'NOT ADMISSIBLE'}"
        + ("" if report["admissible"] else f" (fails: {', '.join(report['failed'])})"),
    ]
    return "\n".join(lines)
