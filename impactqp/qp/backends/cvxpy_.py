"""Any QP solver installed for cvxpy (``"cvxpy"`` means ``"cvxpy:CLARABEL"``).

Programs that carry a ``cache_owner`` are compiled once per (owner, tag, solver) with c as a
``cp.Parameter`` (DPP): later solves on the same structure pay only the re-solve. The cache
holds the owner weakly, so it disappears with the problem structure. The parameter sits in
the linear term only (a parametrized quadratic term would make cvxpy build dense tensors).
"""

from __future__ import annotations

import weakref

import cvxpy as cp
import numpy as np

from ...errors import InputError, SolverError, UnknownBackendError
from ..program import QPSolution, QuadraticProgram
from . import tolerance_options

_CACHE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()

#: plain ``"cvxpy"`` runs Clarabel (a dependency of impactqp) through cvxpy
DEFAULT_SOLVER = "CLARABEL"

MAX_VARIABLES = 15_000
"""Most variables cvxpy is given: compiling the quadratic term forms a dense n × n block
(measured peak memory 0.95 GB at 10⁴ variables, 1.9 GB at 1.5·10⁴; 10⁵ would need ~80 GB)."""


def unsuitable(qp: QuadraticProgram) -> str | None:
    if qp.n_vars > MAX_VARIABLES:
        return (f"'cvxpy' forms a dense n × n matrix when it compiles the program (8n² bytes: "
                f"~{8e-9 * qp.n_vars ** 2:.3g} GB for n = {qp.n_vars}); it takes at most "
                f"{MAX_VARIABLES} variables. Use 'clarabel' (the same solver on sparse data) "
                "or 'auto'")
    return None


def _compile(qp: QuadraticProgram):
    """(problem, x, c parameter, constraint) for the program's fixed data P, A, b."""
    x = cp.Variable(qp.n_vars)
    c = cp.Parameter(qp.n_vars)
    cons = [qp.constraint_matrix() @ x >= qp.constraint_rhs()]
    prob = cp.Problem(cp.Minimize(0.5 * cp.quad_form(x, cp.psd_wrap(qp.P)) + c @ x), cons)
    return prob, x, c, cons[0]


def _compiled(qp: QuadraticProgram, solver: str | None):
    if qp.cache_owner is None:
        return _compile(qp)
    per_owner = _CACHE.setdefault(qp.cache_owner, {})
    key = (qp.cache_tag, solver, qp.n_vars, qp.n_constraints)
    entry = per_owner.get(key)
    if entry is None or not np.array_equal(entry[1], qp.constraint_rhs()):
        entry = (_compile(qp), qp.constraint_rhs().copy())
        per_owner[key] = entry
    return entry[0]


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None,
          options: dict | None = None) -> QPSolution:
    if solver is not None and solver.upper() not in cp.installed_solvers():
        raise UnknownBackendError(f"backend 'cvxpy:{solver}': that solver is not installed "
                                  "for cvxpy; installed: "
                                  f"{', '.join(cp.installed_solvers())}")
    name = solver.upper() if solver else DEFAULT_SOLVER
    prob, x, c, con = _compiled(qp, name)
    c.value = np.asarray(qp.c, dtype=float)
    try:
        prob.solve(solver=name, **{**tolerance_options(name, tol), **(options or {})})
    except TypeError as exc:  # a keyword the solver does not take
        raise InputError(f"cvxpy ({name}) options {options}: {exc}") from exc
    except (cp.error.SolverError, ValueError) as exc:
        raise SolverError(f"cvxpy ({solver or 'default'}) failed: {exc}") from exc
    if prob.status not in ("optimal", "optimal_inaccurate") or x.value is None:
        raise SolverError(f"cvxpy ({solver or 'default'}) ended with status {prob.status!r}")
    used = prob.solver_stats.solver_name if prob.solver_stats else (solver or "default")
    return QPSolution(x=np.asarray(x.value, float), y=np.asarray(con.dual_value, float),
                      status=prob.status, backend=f"cvxpy:{used}")
