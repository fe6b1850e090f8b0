"""Any QP solver installed for cvxpy (``"cvxpy"`` means ``"cvxpy:CLARABEL"``).

Programs that carry a ``cache_owner`` are compiled once per (owner, tag, solver) with c as a
``cp.Parameter`` (DPP): later solves on the same structure pay only the re-solve. The cache
holds the owner weakly, so it disappears with the problem structure. The parameter sits in
the linear term only (a parametrized quadratic term would make cvxpy build dense tensors).

Cone programs (:class:`~impactqp.qp.cones.ConeProgram`) are built with fixed data each time
(no parameter), the second-order cones of one size as one ``cp.SOC`` over rows; any conic
solver of cvxpy takes them (Clarabel by default, ECOS or SCS by name).

impactqp depends on ``cvxpy-base`` (cvxpy without bundled solvers): Clarabel and OSQP come
with impactqp, ``pip install 'impactqp[solvers]'`` adds SCS, ECOS, HiGHS, PIQP and DAQP, and a
solver that is not installed is refused by name with that extra. Solvers run quietly
(:mod:`.quiet`).
"""

from __future__ import annotations

import weakref

import cvxpy as cp
import numpy as np
import scipy.sparse as sp

from ...errors import InputError, SolverError
from ..cones import ConeProgram, ConeSolution
from ..program import QPSolution, QuadraticProgram
from . import tolerance_options
from .quiet import quiet
from .solvers import missing_solver

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


def installed_solvers() -> tuple[str, ...]:
    """The solvers installed for cvxpy, as cvxpy spells them (``"CLARABEL"``, ``"SCS"``)."""
    return tuple(cp.installed_solvers())


def _solver_name(solver: str | None) -> str:
    """cvxpy's name of ``solver`` (the default for None).

    Raises
    ------
    UnknownBackendError
        A solver not installed for cvxpy, named with the extra that installs it.
    """
    name = (solver or DEFAULT_SOLVER).upper()
    installed = installed_solvers()
    if name not in installed:
        raise missing_solver("cvxpy", name, installed)
    return name


def _run(prob: cp.Problem, x: cp.Variable, name: str, tol: float,
         options: dict | None) -> str:
    """Solve ``prob`` with solver ``name``; the solver's name as cvxpy reports it."""
    try:
        with quiet(options):
            prob.solve(solver=name, **{**tolerance_options(name, tol), **(options or {})})
    except TypeError as exc:  # a keyword the solver does not take
        raise InputError(f"cvxpy ({name}) options {options}: {exc}") from exc
    except (cp.error.SolverError, ValueError) as exc:
        raise SolverError(f"cvxpy ({name}) failed: {exc}") from exc
    if prob.status not in ("optimal", "optimal_inaccurate") or x.value is None:
        raise SolverError(f"cvxpy ({name}) ended with status {prob.status!r}")
    return prob.solver_stats.solver_name if prob.solver_stats else name


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None,
          options: dict | None = None) -> QPSolution:
    name = _solver_name(solver)
    prob, x, c, con = _compiled(qp, name)
    c.value = np.asarray(qp.c, dtype=float)
    used = _run(prob, x, name, tol, options)
    return QPSolution(x=np.asarray(x.value, float), y=np.asarray(con.dual_value, float),
                      status=prob.status, backend=f"cvxpy:{used}")


def solve_cone(program: ConeProgram, *, tol: float = 1e-10, solver: str | None = None,
               options: dict | None = None) -> ConeSolution:
    """Solve a cone program through cvxpy; the multipliers are read back in the program's
    convention (Px + c + Aᵀz = 0, z ∈ K*)."""
    name = _solver_name(solver)
    A = sp.csr_matrix(program.A)
    b = program.b
    x = cp.Variable(program.n_vars)
    parts: list[tuple[np.ndarray, cp.Constraint]] = []
    for key, rows in program.blocks.items():
        size = int(key.split(":")[1]) if key.startswith("soc:") else 0
        if key == "zero":  # A x = b: cvxpy's multiplier of this equation is z itself
            parts.append((rows, A[rows] @ x == b[rows]))
        elif key == "nonnegative" or size == 1:  # a second-order cone of size 1 is t ≥ 0
            parts.append((rows, b[rows] - A[rows] @ x >= 0))
        else:  # one cp.SOC for all cones of this size: t_j ≥ ‖w_j‖, row j of W
            idx = rows.reshape(-1, size)
            t = b[idx[:, 0]] - A[idx[:, 0]] @ x
            w = b[idx[:, 1:].ravel()] - A[idx[:, 1:].ravel()] @ x
            parts.append((idx, cp.SOC(t, cp.reshape(w, (idx.shape[0], size - 1), order="C"),
                                      axis=1)))
    objective = program.c @ x
    if program.P is not None:
        objective = objective + 0.5 * cp.quad_form(x, cp.psd_wrap(program.P))
    prob = cp.Problem(cp.Minimize(objective), [con for _, con in parts])
    used = _run(prob, x, name, tol, options)
    z = np.zeros(program.n_constraints)
    for rows, con in parts:
        if isinstance(con, cp.SOC):
            t_dual, w_dual = con.dual_value
            z[rows[:, 0]] = np.ravel(t_dual)
            z[rows[:, 1:]] = np.reshape(w_dual, (rows.shape[0], -1))
        else:
            z[rows] = con.dual_value
    xv = np.asarray(x.value, float)
    return ConeSolution(x=xv, z=z, s=b - A @ xv, status=prob.status, backend=f"cvxpy:{used}",
                        iterations=getattr(prob.solver_stats, "num_iters", None))
