"""Clarabel through its own Python API (no cvxpy in the loop).

Ax ≥ b is passed as −Ax + s = −b with s in the non-negative cone; Clarabel's dual z of
that cone is then the multiplier y ≥ 0 of Ax ≥ b. A cone program
(:class:`~impactqp.qp.cones.ConeProgram`) is Clarabel's own standard form and goes in as it is.
A frictional contact problem is solved as a fixed point of such cone programs
(:func:`impactqp.qp.friction.methods.socp_route`).

In a process forked from the one that imported this module, Clarabel runs on one thread
(``max_threads = 1``). Its sparse factorization spreads large problems (hundreds of contacts)
over a thread pool that lives as long as the process; a fork copies the pool's bookkeeping but
not its threads, so a forked copy of a process that had used the pool waits for them for
ever. One thread gives the same answer, bit for bit (measured on KaplasTower, 570 contacts).
"""

from __future__ import annotations

import os

import clarabel
import numpy as np
import scipy.sparse as sp

from ...errors import InputError, SolverError
from ..cones import ConeProgram, ConeSolution
from ..friction import FrictionSolution
from ..friction.methods import socp
from ..friction.newton import FrictionData
from ..program import QPSolution, QuadraticProgram

_GOOD = {"Solved": "solved", "AlmostSolved": "solved_inaccurate"}
_IMPORTED_IN = os.getpid()
"""The process that imported this module: any other one that has it was forked."""


def settings(tol: float, max_iter: int = 200) -> clarabel.DefaultSettings:
    """Clarabel settings with every tolerance at ``tol`` and no printing; one thread in a
    forked process (the thread pool of the process it was forked from is not there)."""
    s = clarabel.DefaultSettings()
    s.verbose = False
    if os.getpid() != _IMPORTED_IN:
        s.max_threads = 1
    s.max_iter = max_iter
    s.tol_gap_abs = s.tol_gap_rel = s.tol_feas = tol
    s.tol_ktratio = min(s.tol_ktratio, 1e-8)
    return s


def settings_with(tol: float, options: dict | None) -> clarabel.DefaultSettings:
    """:func:`settings` with the user's ``options`` set on top (InputError for a name
    Clarabel's settings do not have)."""
    s = settings(tol)
    for name, value in (options or {}).items():
        if not hasattr(s, name):
            known = ", ".join(n for n in dir(s) if not n.startswith("_"))
            raise InputError(f"clarabel has no setting {name!r}; it has: {known}")
        try:
            setattr(s, name, value)
        except (TypeError, ValueError) as exc:
            raise InputError(f"clarabel setting {name}={value!r}: {exc}") from exc
    return s


def run(P, q, A, b, cones, tol: float, options: dict | None = None):
    """Run Clarabel on its own standard form; raise SolverError unless (almost) solved."""
    P = sp.triu(sp.csc_matrix(P), format="csc")
    config = settings_with(tol, options)
    try:
        sol = clarabel.DefaultSolver(P, np.asarray(q, float), sp.csc_matrix(A),
                                     np.asarray(b, float), cones, config).solve()
    except Exception as exc:  # Clarabel reports every failure as a bare Exception
        raise SolverError(f"clarabel failed: {exc}") from exc
    status = str(sol.status).split(".")[-1]
    if status not in _GOOD:
        raise SolverError(f"clarabel ended with status {status}")
    return sol, _GOOD[status]


def solve(qp: QuadraticProgram, *, tol: float = 1e-10, solver: str | None = None,
          options: dict | None = None) -> QPSolution:
    A = sp.csc_matrix(qp.constraint_matrix())
    sol, status = run(qp.P, qp.c, -A, -qp.constraint_rhs(),
                      [clarabel.NonnegativeConeT(qp.n_constraints)], tol, options)
    return QPSolution(x=np.array(sol.x), y=np.array(sol.z), status=status, backend="clarabel",
                      iterations=int(sol.iterations))


_CONE_TYPES = {"zero": clarabel.ZeroConeT, "nonnegative": clarabel.NonnegativeConeT,
               "soc": clarabel.SecondOrderConeT}


def solve_cone(program: ConeProgram, *, tol: float = 1e-10, solver: str | None = None,
               options: dict | None = None) -> ConeSolution:
    """Solve a cone program in Clarabel's standard form (the same convention as
    :class:`~impactqp.qp.cones.ConeProgram`: Ax + s = b, s ∈ K, z ∈ K*)."""
    P = sp.csc_matrix((program.n_vars, program.n_vars)) if program.P is None else program.P
    cones = [_CONE_TYPES[cone.kind](cone.size) for cone in program.cones]
    sol, status = run(P, program.c, program.A, program.b, cones, tol, options)
    return ConeSolution(x=np.array(sol.x), z=np.array(sol.z), s=np.array(sol.s), status=status,
                        backend="clarabel", iterations=int(sol.iterations))


def solve_friction(data: FrictionData, start: np.ndarray | None, *, tol: float,
                   method: str) -> FrictionSolution:
    """The fixed point of second-order cone programs from ``start``
    (:func:`impactqp.qp.friction.methods.socp`)."""
    return socp(data, start, tol)
