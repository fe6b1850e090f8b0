"""Any solver installed for qpsolvers (``"qpsolvers:NAME"``, or ``"qpsolvers"`` for the best
installed one); Ax ≥ b becomes Gx ≤ h."""

from __future__ import annotations

import numpy as np
import qpsolvers

from ...base.arrays import as_dense
from ...errors import BackendUnsuitableError, InputError, SolverError, UnknownBackendError
from ..program import QPSolution, QuadraticProgram
from . import tolerance_options
from .exact import MAX_DENSE_VARIABLES

PREFERRED_DENSE = ("daqp", "quadprog", "piqp", "clarabel", "proxqp", "osqp", "highs", "ecos")
"""Solvers tried for plain ``"qpsolvers"`` on dense programs, best first (benchmarks/: the
active-set solvers daqp and quadprog are exact and fastest on small dense impacts)."""

PREFERRED_SPARSE = ("piqp", "clarabel", "proxqp", "osqp", "highs", "scs")
"""The same for sparse programs (interior-point piqp is 3–5× faster than Clarabel on sparse
impacts of 10⁴ contacts)."""


def best_solver(qp: QuadraticProgram) -> str:
    """The first installed solver of the preference list for ``qp``'s storage.

    Raises
    ------
    UnknownBackendError
        When qpsolvers has no solver for it installed.
    """
    order = PREFERRED_SPARSE if qp.sparse else PREFERRED_DENSE
    for name in order:
        if name in qpsolvers.available_solvers:
            return name
    raise UnknownBackendError(f"backend 'qpsolvers': none of {', '.join(order)} is installed "
                              "(pip install 'impactqp[solvers]' adds daqp, piqp, ecos, quadprog)")


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None,
          options: dict | None = None) -> QPSolution:
    if solver is None:
        solver = best_solver(qp)
    if solver not in qpsolvers.available_solvers:
        raise UnknownBackendError(f"backend 'qpsolvers:{solver}': that solver is not "
                                  "installed; installed: "
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
        sol = qpsolvers.solve_problem(problem, solver=solver,
                                      **{**tolerance_options(solver, tol), **(options or {})})
    except TypeError as exc:  # a keyword the solver does not take
        raise InputError(f"qpsolvers:{solver} options {options}: {exc}") from exc
    except Exception as exc:  # solvers raise their own types; translate them
        raise SolverError(f"qpsolvers:{solver} failed: {exc}") from exc
    if sol.x is None or sol.z is None or not sol.found:
        raise SolverError(f"qpsolvers:{solver} found no solution")
    return QPSolution(x=np.asarray(sol.x, float), y=np.asarray(sol.z, float),
                      status="solved", backend=f"qpsolvers:{solver}")
