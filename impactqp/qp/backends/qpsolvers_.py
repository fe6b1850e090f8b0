"""Any solver installed for qpsolvers (``"qpsolvers:NAME"``); Ax ≥ b becomes Gx ≤ h."""

from __future__ import annotations

import numpy as np
import qpsolvers

from ...base.arrays import as_dense
from ...errors import BackendUnsuitableError, SolverError, UnknownBackendError
from ..program import QPSolution, QuadraticProgram
from . import tolerance_options
from .exact import MAX_DENSE_VARIABLES


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None) -> QPSolution:
    if solver not in qpsolvers.available_solvers:
        raise UnknownBackendError(f"qpsolvers solver {solver!r} is not installed; installed: "
                                  f"{', '.join(qpsolvers.available_solvers)} "
                                  "(pip install 'impactqp[solvers]' adds more)")
    sparse_ok = solver in qpsolvers.sparse_solvers
    if not sparse_ok and qp.sparse and qp.n_vars > MAX_DENSE_VARIABLES:
        raise BackendUnsuitableError(f"qpsolvers:{solver} works on dense matrices; {qp.n_vars} "
                                     f"variables of a sparse program are more than "
                                     f"{MAX_DENSE_VARIABLES} (use a sparse solver such as piqp)")
    P, G = qp.P, -qp.constraint_matrix()
    if not sparse_ok:
        P, G = as_dense(P), as_dense(G)
    problem = qpsolvers.Problem(P, np.asarray(qp.c, float), G, -qp.constraint_rhs())
    try:
        sol = qpsolvers.solve_problem(problem, solver=solver, **tolerance_options(solver, tol))
    except Exception as exc:  # solvers raise their own types; translate them
        raise SolverError(f"qpsolvers:{solver} failed: {exc}") from exc
    if sol.x is None or sol.z is None or not sol.found:
        raise SolverError(f"qpsolvers:{solver} found no solution")
    return QPSolution(x=np.asarray(sol.x, float), y=np.asarray(sol.z, float),
                      status="solved", backend=f"qpsolvers:{solver}")
