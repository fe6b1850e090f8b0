"""Normalize a program before a backend sees it, and map the solution back
(docs/theory.md §8, §9).

Backends stop on absolute tolerances and some decide infeasibility from them, so the same
impact in other units (velocities of 1e-200 m/s, masses of 1e12 kg) must reach them as a
program of order one. With x = αs·x̃ (s = 1/√max Pᵢᵢ, α = ‖s c‖_∞), β = α²:

    ½xᵀPx + cᵀx = β (½x̃ᵀP̃x̃ + c̃ᵀx̃),   P̃ = s²P,   c̃ = s c / α,

so P̃ has unit largest diagonal entry and c̃ unit largest entry. Constraints ``Ax ≥ b`` become
``Ax̃ ≥ b / (αs)`` (the same rows when b = 0, as in every impact program, so a chain stays a
chain), and the multipliers of the two programs are related by y = (α/s) ỹ.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from .program import ChainShape, QPSolution, QuadraticProgram


@dataclass(frozen=True)
class Scaling:
    """x = x_scale · x̃ and y = y_scale · ỹ between a program and its normalized form."""

    x_scale: float
    y_scale: float

    def solution(self, sol: QPSolution) -> QPSolution:
        """A solution of the normalized program as one of the original program."""
        if self.x_scale == 1.0 and self.y_scale == 1.0:
            return sol
        return replace(sol, x=sol.x * self.x_scale, y=sol.y * self.y_scale)


def _diagonal_peak(P) -> float:
    d = P.diagonal() if sp.issparse(P) else np.diag(P)
    return float(np.max(np.abs(d), initial=0.0))


def normalize(qp: QuadraticProgram) -> tuple[QuadraticProgram, Scaling]:
    """The normalized program and the scaling back; the program itself (scaling 1) when it
    has nothing to scale (P = 0 or c = 0, whose solution x = 0 needs no solver help)."""
    peak = _diagonal_peak(qp.P)
    if not peak > 0 or not np.isfinite(peak):
        return qp, Scaling(1.0, 1.0)
    s = 1.0 / np.sqrt(peak)
    alpha = float(np.max(np.abs(qp.c), initial=0.0)) * s
    with np.errstate(over="ignore"):
        back = Scaling(alpha * s, alpha / s)
    if not (alpha > 0 and np.isfinite(alpha) and back.x_scale > 0
            and np.isfinite(back.x_scale) and np.isfinite(back.y_scale)):
        return qp, Scaling(1.0, 1.0)  # not representable scaled: leave it as it is
    chain = None if qp.chain is None else ChainShape(
        qp.chain.weights * s * s, qp.chain.left_wall, qp.chain.right_wall,
        None if qp.chain.center is None else qp.chain.center / (alpha * s))
    scaled = QuadraticProgram(
        P=qp.P * (s * s), c=qp.c * (s / alpha), A=qp.A,
        b=None if qp.b is None else qp.b / (alpha * s),
        factor=None if qp.factor is None else qp.factor * s,
        factor_rhs=None if qp.factor_rhs is None else qp.factor_rhs / alpha,
        cache_owner=qp.cache_owner, cache_tag=f"{qp.cache_tag}:unit", chain=chain)
    return scaled, back
