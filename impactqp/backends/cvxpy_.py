"""Any QP solver installed for cvxpy (``"cvxpy"`` uses cvxpy's default choice)."""

from __future__ import annotations

import cvxpy as cp
import numpy as np

from ..errors import SolverError, UnknownBackendError
from ..program import QPSolution, QuadraticProgram


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None) -> QPSolution:
    if solver is not None and solver.upper() not in cp.installed_solvers():
        raise UnknownBackendError(f"cvxpy solver {solver!r} is not installed; installed: "
                                  f"{', '.join(cp.installed_solvers())}")
    x = cp.Variable(qp.n_vars)
    A = qp.constraint_matrix()
    cons = [A @ x >= qp.constraint_rhs()]
    objective = 0.5 * cp.quad_form(x, cp.psd_wrap(qp.P)) + qp.c @ x
    prob = cp.Problem(cp.Minimize(objective), cons)
    try:
        prob.solve(solver=solver.upper() if solver else None)
    except (cp.error.SolverError, ValueError) as exc:
        raise SolverError(f"cvxpy ({solver or 'default'}) failed: {exc}") from exc
    if prob.status not in ("optimal", "optimal_inaccurate") or x.value is None:
        raise SolverError(f"cvxpy ({solver or 'default'}) ended with status {prob.status!r}")
    name = prob.solver_stats.solver_name if prob.solver_stats else (solver or "default")
    return QPSolution(x=np.asarray(x.value, float), y=np.asarray(cons[0].dual_value, float),
                      status=prob.status, backend=f"cvxpy:{name}")
