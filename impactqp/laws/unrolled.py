"""Straight-line float programs for single small impacts (docs/theory.md §8, §9).

For an impact with a few contacts the arithmetic of a solve is a few dozen products, and the
cost of a call is the interpreter's: loops, list building and, worse, numpy's per-call
overhead on 2-vectors. This module writes, once per problem structure and kind of law, a
Python function in which every operator of the structure is spelled out with its entries as
constants (exact ``repr`` round trips, zero entries dropped) and compiles it. The function

1. forms γ⁻ = Wᵀu⁻ and the law's q = (I + E)γ⁻,
2. solves the LCP ``0 ≤ Λ ⟂ GΛ + q ≥ 0`` by the supports of the prepared active-set kernel
   (:class:`impactqp.qp.active_set.ActiveSetKernel`: the same inverses, order and
   acceptance tolerances), starting from the support that fitted last,
3. recovers u⁺ = u⁻ + M⁻¹WΛ and recomputes every residual of the law's certificate
   (docs/theory.md §8) with the formulas of :func:`impactqp.model.residuals.law_residuals`,
   in the same units,

and returns nothing unless every residual is finite and within the tolerance: the decision to
accept is made here, before any result exists. Only the entries of the structure enter the
source (as float literals); the velocities and coefficients are arguments.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Callable, Sequence

import numpy as np

from ..model.structure import ImpactStructure
from ..qp.active_set import SUPPORT_TOL, ActiveSetKernel

KINDS = ("moreau", "newton", "fremond")
"""The laws' matrices E: εI (Moreau, with its energy balance and duality gap), diag(e)
(local Newton) and a full E (Frémond)."""

SCALE_RANGE = (1e-60, 1e60)
"""Velocity scales whose squares need no rescaling (as in normalized_rows); outside, the
program declines and the general path, which rescales, answers."""

FloatProgram = Callable[[Sequence[float], Sequence[float], float], tuple | None]

COMPILE_AFTER = 3
"""A structure's program is compiled at its third solve by a law of one kind. Compiling
costs 1–5 ms (as much as ~100 solves), so structures met once or twice (a simulation's
changing contact sets) are answered by the array path instead."""

_PROGRAMS: dict[tuple[int, str], FloatProgram | int] = {}
"""By (id of the structure, kind): its compiled program, or how often it was asked for so
far. An entry leaves when its structure is collected (before the id can be reused)."""


def program_for(structure: ImpactStructure, kind: str,
                kernel: Callable[[ImpactStructure], ActiveSetKernel]) -> FloatProgram | None:
    """The compiled program of ``structure`` for a law of ``kind``, once it has been asked
    for :data:`COMPILE_AFTER` times (None before).

    Parameters
    ----------
    structure : ImpactStructure
        A dense structure with at most :data:`impactqp.qp.active_set.MAX_CONTACTS` contacts.
    kind : {"moreau", "newton", "fremond"}
        Which E the program takes (see :data:`KINDS`).
    kernel : callable
        ``kernel(structure)`` returns the prepared kernel of the structure's Delassus matrix
        (its supports are spelled out); called only when the program is made.

    Returns
    -------
    callable or None
        ``program(u_minus, coefficients, tol)`` with u⁻ as n floats and the coefficients as
        (ε,), (e₁, …, e_m) or E row by row; it returns ``(u⁺, Λ, z, residuals)`` (tuples of
        floats, z None except for Moreau's law, residuals in the order of
        :class:`impactqp.laws.certificate.Certificate` without ``tol``) or None when no
        support fits or a residual misses ``tol``.
    """
    key = (id(structure), kind)
    program = _PROGRAMS.get(key, 0)
    if type(program) is not int:
        return program
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    if program == 0:
        weakref.finalize(structure, _PROGRAMS.pop, key, None)
    if program + 1 < COMPILE_AFTER:
        _PROGRAMS[key] = program + 1
        return None
    compiled = _PROGRAMS[key] = _compile(structure, kind, kernel(structure))
    return compiled


def _combination(coefficients: Sequence[float], names: Sequence[str]) -> str:
    """Σ cᵢ·nameᵢ as source: zero terms dropped, ±1 without a product, left to right."""
    terms = []
    for c, name in zip(coefficients, names):
        if c == 0.0:
            continue
        terms.append(f" + {name}" if c == 1.0 else f" - {name}" if c == -1.0
                     else f" + {float(c)!r}*{name}")
    if not terms:
        return "0.0"
    text = "".join(terms)
    return text[3:] if text.startswith(" + ") else "-" + text[3:]


def _quadratic(M: Sequence[Sequence[float]], x: Sequence[str]) -> str:
    """xᵀMx as source: Σᵢ xᵢ (Mx)ᵢ."""
    parts = [f"{xi}*({_combination(row, x)})" for row, xi in zip(M, x)
             if any(c != 0.0 for c in row)]
    return " + ".join(parts) or "0.0"


def _largest(names: Sequence[str]) -> str:
    """max abs(xᵢ) as source (``max`` needs two arguments)."""
    terms = [f"abs({name})" for name in names]
    return terms[0] if len(terms) == 1 else f"max({', '.join(terms)})"


def _names(prefix: str, count: int) -> list[str]:
    return [f"{prefix}{i}" for i in range(count)]


def _support_source(index: int, found: tuple, m: int) -> list[str]:
    """A function trying one support J: Λ_J = −G_JJ⁻¹q_J ≥ lt and (GΛ + q)_F ≥ wt."""
    J, F, inv, GFJ = (x.tolist() for x in found)
    q, lam = _names("q", m), _names("l", m)
    lines = [f"def _support{index}({', '.join(q)}, lt, wt):"]
    for j, row in zip(J, inv):
        lines.append(f"    l{j} = -({_combination(row, [q[i] for i in J])})")
    lines.append("    if " + " or ".join(f"l{j} < lt" for j in J) + ":")
    lines.append("        return None")
    if F:
        lines.append("    if " + " or ".join(
            f"({_combination(row, [lam[j] for j in J])}) + q{f} < wt"
            for f, row in zip(F, GFJ)) + ":")
        lines.append("        return None")
    out = [f"l{i} if l{i} > 0.0 else 0.0" if i in J else "0.0" for i in range(m)]
    lines.append(f"    return ({', '.join(out)},)")
    return lines


def _law_terms(kind: str, m: int) -> list[str]:
    """q = (I + E)γ⁻ from the coefficients ``e``."""
    g = _names("g", m)
    if kind == "moreau":
        return ["    c = 1.0 + e[0]"] + [f"    q{i} = c*g{i}" for i in range(m)]
    if kind == "newton":
        return [f"    q{i} = (1.0 + e[{i}])*g{i}" for i in range(m)]
    return [f"    q{i} = g{i} + ({' + '.join(f'e[{i * m + j}]*{g[j]}' for j in range(m))})"
            for i in range(m)]


def _finite(values) -> bool:
    """Every entry finite (constants must be float literals)."""
    return bool(np.isfinite(np.asarray(values, dtype=float)).all())


def _declines(u: Sequence[float], e: Sequence[float], tol: float) -> None:
    """The program of a structure that cannot be written with float literals."""
    return None


def _compile(structure: ImpactStructure, kind: str, kernel: ActiveSetKernel) -> FloatProgram:
    rows = structure.float_rows
    if not all(map(_finite, (*rows, [kernel.scale]))):
        return _declines  # operators beyond the float range (extreme units): arrays rescale
    n, m = structure.n, structure.m
    u, q, lam = _names("u", n), _names("q", m), _names("l", m)
    p, d = _names("p", n), _names("d", n)
    s = rows.contact_scale
    lines: list[str] = []
    supports = []
    for index in range(kernel.n_supports):
        found = kernel.support(index)
        if found is not None and _finite(found[2]) and _finite(found[3]):
            lines += _support_source(index, found, m)
            supports.append(index)
    low, high = SCALE_RANGE
    lines += [
        "def program(u, e, tol):",
        f"    {', '.join(u)}, = u",
        f"    a = {_largest(u)}",
        f"    if not {low!r} < a < {high!r}:",
        "        return None",
    ]
    lines += [f"    g{i} = {_combination(row, u)}" for i, row in enumerate(rows.Wt)]
    lines += _law_terms(kind, m)
    # the LCP (docs/theory.md §9): Λ = 0 when q ≥ 0, else the first support that fits
    lines += [
        f"    if {' and '.join(f'{x} >= 0.0' for x in q)}:",
        f"        {' = '.join(lam)} = 0.0",
        "    else:",
        f"        qs = {_largest(q)}",
        f"        lt, wt = -{SUPPORT_TOL!r}*qs/{float(kernel.scale)!r}, -{SUPPORT_TOL!r}*qs",
        "        start = STATE[0]",
        "        for index, support in ORDERS[start]:",
        f"            found = support({', '.join(q)}, lt, wt)",
        "            if found is not None:",
        "                STATE[0] = POSITION[index]",
        "                break",
        "        else:",
        "            return None",
        f"        {', '.join(lam)}, = found",
    ]
    # u⁺ and the residuals of docs/theory.md §8 (as law_residuals computes them)
    lines += [f"    j{i} = {_combination(row, lam)}" for i, row in enumerate(rows.Minv_W)]
    lines += [f"    p{i} = u{i} + j{i}" for i in range(n)]
    lines += [f"    d{i} = (p{i} - u{i}) - j{i}" for i in range(n)]
    lines += [
        f"    V2 = {_quadratic(rows.M, u)}",
        "    if not V2 > 0.0:",
        "        return None",
        "    V = sqrt(V2)",
        f"    mom = sqrt(max({_quadratic(rows.M, d)}, 0.0))/V",
        f"    sign = max(0.0, {', '.join(f'-(l{i}*{s[i]!r})/V' for i in range(m))})",
    ]
    lines += [f"    w{i} = ({_combination(row, p)}) + (q{i} - g{i})"
              for i, row in enumerate(rows.Wt)]
    lines += [
        f"    feas = max(0.0, {', '.join(f'-w{i}/({s[i]!r}*V)' for i in range(m))})",
        f"    {', '.join(f'c{i}' for i in range(m))}, = "
        f"{', '.join(f'abs(l{i}*w{i})' for i in range(m))},",
        f"    comp = max({', '.join(f'c{i}' for i in range(m))}, 0.0)/V2",
    ]
    if kind == "moreau":
        z, zp = _names("z", n), _names("y", n)
        lines += [f"    z{i} = (p{i} + e[0]*u{i})/c" for i in range(n)]
        lines += [f"    y{i} = u{i} - z{i}" for i in range(n)]
        cross = " + ".join(f"z{i}*({_combination(row, zp)})" for i, row in enumerate(rows.M))
        lines += [
            f"    energy = 2.0*e[0]*abs({cross})/V2",
            f"    gap = ({' + '.join(f'c{i}' for i in range(m))})/V2 + mom*mom",
            "    if (mom <= tol and sign <= tol and feas <= tol and comp <= tol"
            " and energy <= tol and gap <= tol):",
            f"        return ({', '.join(p)},), ({', '.join(lam)},), ({', '.join(z)},), "
            "(mom, sign, feas, comp, energy, gap)",
            "    return None",
        ]
    else:
        lines += [
            "    if mom <= tol and sign <= tol and feas <= tol and comp <= tol:",
            f"        return ({', '.join(p)},), ({', '.join(lam)},), None, "
            "(mom, sign, feas, comp, None, None)",
            "    return None",
        ]
    namespace: dict = {"sqrt": math.sqrt, "STATE": [0]}
    exec(compile("\n".join(lines), f"<impactqp float program {n}x{m} {kind}>", "exec"),
         namespace)
    functions = [namespace[f"_support{i}"] for i in supports]
    pairs = list(zip(supports, functions))
    namespace["ORDERS"] = tuple(tuple(pairs[k:] + pairs[:k]) for k in range(len(pairs))) or ((),)
    namespace["POSITION"] = {index: k for k, index in enumerate(supports)}
    return namespace["program"]
