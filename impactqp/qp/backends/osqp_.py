"""OSQP (operator splitting): l ≤ Ax ≤ u with u = +∞; OSQP's y is ≤ 0 on active lower bounds.

OSQP's own polishing prints to stdout; impactqp polishes every answer itself instead
(:mod:`impactqp.qp.polish`).
"""

from __future__ import annotations

import numpy as np
import osqp
import scipy.sparse as sp

from ...errors import InputError, SolverError
from ..program import QPSolution, QuadraticProgram

MAX_VARIABLES = 50_000
"""Most variables OSQP is given: its first-order iterations reach impactqp's tolerance on a
chain of 3·10⁴ balls in 0.8 s but take ~40 s at 10⁵ (measured)."""


def unsuitable(qp: QuadraticProgram) -> str | None:
    if qp.n_vars > MAX_VARIABLES:
        return (f"'osqp' converges too slowly to impactqp's tolerance on {qp.n_vars} variables "
                f"(at most {MAX_VARIABLES}: ~40 s measured at 10⁵); use 'clarabel', "
                "'qpsolvers:piqp' or 'auto'")
    return None


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None,
          options: dict | None = None) -> QPSolution:
    P = sp.triu(sp.csc_matrix(qp.P), format="csc")
    A = sp.csc_matrix(qp.constraint_matrix())
    upper = np.full(qp.n_constraints, np.inf)
    settings = {"verbose": False, "eps_abs": tol, "eps_rel": tol, "max_iter": 200000,
                "polishing": False, **(options or {})}
    prob = osqp.OSQP()
    try:
        prob.setup(P, np.asarray(qp.c, float), A, qp.constraint_rhs(), upper, **settings)
    except (TypeError, ValueError) as exc:  # a setting OSQP does not know or accept
        if options:
            raise InputError(f"osqp settings {options}: {exc}") from exc
        raise SolverError(f"osqp failed: {exc}") from exc
    try:
        res = prob.solve()
    except Exception as exc:
        raise SolverError(f"osqp failed: {exc}") from exc
    status = str(res.info.status)
    if res.x is None or "solved" not in status.lower() or "unsolved" in status.lower():
        raise SolverError(f"osqp ended with status {status!r}")
    return QPSolution(x=np.array(res.x), y=-np.array(res.y), status=status, backend="osqp",
                      iterations=int(res.info.iter))
