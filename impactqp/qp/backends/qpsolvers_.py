"""Any solver installed for qpsolvers (``"qpsolvers:NAME"``, or ``"qpsolvers"`` for the best
installed one); Ax ≥ b becomes Gx ≤ h.

Clarabel and OSQP come with impactqp; ``pip install 'impactqp[solvers]'`` adds daqp, piqp,
quadprog, ecos, scs and highs, and a solver that is not installed is refused by name with that
extra. Solvers that take sparse matrices only are given them in CSC storage (no conversion
warning), and every solver runs quietly (:mod:`.quiet`).
"""

from __future__ import annotations

import numpy as np
import qpsolvers
import scipy.sparse as sp

from ...base.arrays import as_dense
from ...errors import BackendUnsuitableError, InputError, SolverError, UnknownBackendError
from ..program import QPSolution, QuadraticProgram
from . import tolerance_options
from .exact import MAX_DENSE_VARIABLES
from .quiet import quiet
from .solvers import missing_solver

PREFERRED_DENSE = ("daqp", "quadprog", "piqp", "clarabel", "proxqp", "osqp", "highs", "ecos")
"""Solvers tried for plain ``"qpsolvers"`` on dense programs, best first (benchmarks/: the
active-set solvers daqp and quadprog are exact and fastest on small dense impacts)."""

PREFERRED_SPARSE = ("piqp", "clarabel", "proxqp", "osqp", "highs", "scs")
"""The same for sparse programs (interior-point piqp is 3–5× faster than Clarabel on sparse
impacts of 10⁴ contacts)."""


def installed_solvers() -> tuple[str, ...]:
    """The solvers installed for qpsolvers, as qpsolvers spells them (``"daqp"``)."""
    return tuple(qpsolvers.available_solvers)


def best_solver(qp: QuadraticProgram) -> str:
    """The first installed solver of the preference list for ``qp``'s storage.

    Raises
    ------
    UnknownBackendError
        When qpsolvers has no solver for it installed.
    """
    order = PREFERRED_SPARSE if qp.sparse else PREFERRED_DENSE
    installed = installed_solvers()
    for name in order:
        if name in installed:
            return name
    raise UnknownBackendError(f"backend 'qpsolvers': none of {', '.join(order)} is installed "
                              "(pip install 'impactqp[solvers]' adds daqp, piqp, quadprog, "
                              "ecos, scs and highs)")


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None,
          options: dict | None = None) -> QPSolution:
    if solver is None:
        solver = best_solver(qp)
    installed = installed_solvers()
    if solver not in installed:
        raise missing_solver("qpsolvers", solver, installed)
    sparse_ok = solver in qpsolvers.sparse_solvers
    if not sparse_ok and qp.sparse and qp.n_vars > MAX_DENSE_VARIABLES:
        raise BackendUnsuitableError(f"qpsolvers:{solver} works on dense matrices; {qp.n_vars} "
                                     f"variables of a sparse program are more than "
                                     f"{MAX_DENSE_VARIABLES} (use a sparse solver such as piqp)")
    P, G = qp.P, -qp.constraint_matrix()
    if not sparse_ok:
        P, G = as_dense(P), as_dense(G)
    elif solver not in qpsolvers.dense_solvers:  # it would convert them itself, warning
        P, G = sp.csc_matrix(P), sp.csc_matrix(G)
    problem = qpsolvers.Problem(P, np.asarray(qp.c, float), G, -qp.constraint_rhs())
    try:
        with quiet(options):
            sol = qpsolvers.solve_problem(
                problem, solver=solver, **{**tolerance_options(solver, tol), **(options or {})})
    except TypeError as exc:  # a keyword the solver does not take
        raise InputError(f"qpsolvers:{solver} options {options}: {exc}") from exc
    except Exception as exc:  # solvers raise their own types; translate them
        raise SolverError(f"qpsolvers:{solver} failed: {exc}") from exc
    if sol.x is None or sol.z is None or not sol.found:
        raise SolverError(f"qpsolvers:{solver} found no solution")
    return QPSolution(x=np.asarray(sol.x, float), y=np.asarray(sol.z, float),
                      status="solved", backend=f"qpsolvers:{solver}")
