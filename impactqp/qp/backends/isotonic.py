"""The ``"isotonic"`` backend: velocity programs of 1-D chains by weighted isotonic
regression, exact and O(N) (docs/theory.md §5).

The program ``min ½vᵀDv − (Du⁻)ᵀv`` subject to the chain's gap rows (and wall rows) is the
D-weighted isotonic regression of u⁻ (clipped at 0 on a wall side); its multipliers are the
impulses of ``D(z − u⁻) = WΛ``, found by anchored prefix sums (:mod:`impactqp.qp.isotonic`).
"""

from __future__ import annotations

import numpy as np

from ..isotonic import chain_moreau_batch, chain_projection
from ..program import QPSolution, QuadraticProgram


def unsuitable(qp: QuadraticProgram) -> str | None:
    if qp.chain is None:
        return ("'isotonic' solves the velocity form of 1-D chains built by iq.chain or "
                "iq.newtons_cradle only")
    return None


def _shift(qp: QuadraticProgram, C: np.ndarray) -> np.ndarray:
    """u⁻ from the linear term c = −Du⁻ (programs that do not carry it as their center)."""
    return -C / qp.chain.weights


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None) -> QPSolution:
    shape = qp.chain
    u = shape.center if shape.center is not None else _shift(qp, qp.c)
    z, lam = chain_projection(shape.weights, u, shape.left_wall, shape.right_wall)
    return QPSolution(x=z, y=lam, status="solved", backend="isotonic")


def solve_many(qp: QuadraticProgram, C: np.ndarray, *, tol: float = 1e-10,
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(X, Y, solved mask) for the rows of C as linear terms."""
    shape = qp.chain
    sol = chain_moreau_batch(shape.weights, _shift(qp, C), 0.0, left_wall=shape.left_wall,
                             right_wall=shape.right_wall)
    return sol.z, sol.impulses, np.ones(C.shape[0], dtype=bool)
