"""Single small impacts on Python floats: the pipeline's first fast path (docs/theory.md §8, §9).

For a dense impact with a few contacts, numpy's per-call overhead dwarfs the arithmetic. This
path runs the prepared active-set kernel on Python floats and recomputes every residual of the
law's certificate (docs/theory.md §8: momentum, Λ ≥ 0, law feasibility, complementarity and,
for Moreau's law, the energy balance and the duality gap) with the same formulas as
:func:`impactqp.model.residuals.law_residuals`, in the same units. An answer whose residuals
miss the tolerance is not returned: the pipeline goes on to the general path.
"""

from __future__ import annotations

import math
import time
from operator import mul

import numpy as np

from ..model.problem import ImpactProblem
from ..qp.backends.kernel import prepared_for
from .base import Answer, ImpactLaw
from .certificate import Certificate
from .complementarity import Fremond, Newton
from .moreau import Moreau
from .result import ImpactResult

SMALL_CONTACTS = 4
"""Most contacts the float path takes (beyond, arrays are cheaper than loops)."""

SMALL_DOF = 12
"""Most degrees of freedom the float path takes."""

SCALE_RANGE = (1e-60, 1e60)
"""Velocity scales whose squares need no rescaling (as in normalized_rows)."""


def applies(problem: ImpactProblem, law: ImpactLaw, backend: str, form: str) -> bool:
    """Whether the float path may answer (it may still decline after trying)."""
    st = problem.structure
    return (backend in ("auto", "kernel") and form in ("auto", "impulse") and not st.sparse
            and 0 < st.m <= SMALL_CONTACTS and st.n <= SMALL_DOF
            and type(law) in (Moreau, Newton, Fremond))


def _q(law: ImpactLaw, gamma: list[float]) -> list[float]:
    """q = (I + E)γ⁻ of the law's LCP."""
    if isinstance(law, Moreau):
        return [(1.0 + law.eps) * g for g in gamma]
    if isinstance(law, Newton):
        e = law.coefficients_for_size(len(gamma))
        return [(1.0 + ei) * g for ei, g in zip(e, gamma)]
    return [g + sum(a * b for a, b in zip(row, gamma))
            for g, row in zip(gamma, law.E.tolist())]


def _dot(row: tuple[float, ...], x: list[float]) -> float:
    return sum(map(mul, row, x))


def _m_norm2(M: tuple[tuple[float, ...], ...], x: list[float]) -> float:
    return sum(map(mul, x, [sum(map(mul, row, x)) for row in M]))


def solve_small(problem: ImpactProblem, law: ImpactLaw, tol: float,
                start: float) -> ImpactResult | None:
    """The certified result by the float path, or None to go on to the general path."""
    st = problem.structure
    rows = st.float_rows
    um = problem.u_minus.tolist()
    scale = max(max(um), -min(um))
    if not SCALE_RANGE[0] < scale < SCALE_RANGE[1]:
        return None
    gamma = [_dot(row, um) for row in rows.Wt]
    q = _q(law, gamma)
    lam = prepared_for(st, "impulse", st.delassus).solve_floats(q)
    if lam is None:
        return None
    jump = [_dot(row, lam) for row in rows.Minv_W]  # M⁻¹WΛ
    up = [u + d for u, d in zip(um, jump)]
    # the residuals of docs/theory.md §8, recomputed from (u⁻, u⁺, Λ)
    V2 = _m_norm2(rows.M, um)
    V = math.sqrt(V2)
    du = [a - b - d for a, b, d in zip(up, um, jump)]
    momentum = math.sqrt(max(_m_norm2(rows.M, du), 0.0)) / V
    s = rows.contact_scale
    impulse_sign = max(0.0, -min(li * si / V for li, si in zip(lam, s)))
    w = [_dot(row, up) + (qi - gi) for row, qi, gi in zip(rows.Wt, q, gamma)]
    law_feasibility = max(0.0, -min(wi / (si * V) for wi, si in zip(w, s)))
    products = [abs(li * wi) for li, wi in zip(lam, w)]
    complementarity = max(products) / V2
    energy = gap = None
    z = None
    if isinstance(law, Moreau):
        e = law.eps
        z = [(a + e * b) / (1.0 + e) for a, b in zip(up, um)]
        zp = [b - a for a, b in zip(z, um)]
        energy = 2.0 * e * abs(sum(map(mul, z, [_dot(row, zp) for row in rows.M]))) / V2
        gap = sum(products) / V2 + momentum * momentum
    cert = Certificate(momentum=momentum, impulse_sign=impulse_sign,
                       law_feasibility=law_feasibility, complementarity=complementarity,
                       energy_balance=energy, tol=tol, duality_gap=gap)
    if not cert.ok:
        return None
    answer = Answer(np.array(up), np.array(lam), None if z is None else np.array(z))
    return ImpactResult(problem, law.name, law.coefficients_for(problem), answer.u_plus,
                        answer.impulses, "kernel", cert, form="impulse", z=answer.z,
                        attempts=["kernel (impulse, on floats): certified"], impact_law=law,
                        solve_time=time.perf_counter() - start)
