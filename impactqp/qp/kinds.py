"""What the certified loop (:func:`impactqp.qp.certified.solve_certified`) needs to know of
each kind of program: how a backend is called on it, at which tolerances, how an iterative
answer is polished, and what is said when nothing passes (docs/theory.md §9).

Three kinds: quadratic programs (forms ``"velocity"`` and ``"impulse"``, normalized to order
one before a backend sees them, polished on their active set), cone programs (``"cone"``) and
local frictional contact problems (``"friction"``, polished by Newton's method, each method
after the first warm-started from the best answer so far where it takes a start).
"""

from __future__ import annotations

from types import ModuleType
from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog

from ..base.definite import symmetric_ldl
from ..errors import CertificateError, NoSolutionError
from ..kernels.friction import project_cones
from .backends import CONE, FRICTION, Backend
from .friction import FrictionSolution
from .friction.newton import FrictionData, newton
from .polish import polish
from .program import QPSolution, QuadraticProgram
from .scaling import Scaling, normalize


class QPKind:
    """Quadratic programs: a backend's ``solve`` on the normalized program (unless it is
    scale-free), retried a hundred times tighter unless exact, polished on its active set."""

    def prepare(self, entry: Backend, program: QuadraticProgram) -> tuple[QuadraticProgram,
                                                                            Scaling]:
        return (program, Scaling(1.0, 1.0)) if entry.scale_free else normalize(program)

    def tolerances(self, entry: Backend, tol: float) -> tuple[float, ...]:
        return (tol,) if entry.exact else (tol, tol * 1e-2)

    def run(self, module: ModuleType, entry: Backend, sub: str | None, prepared: Any,
            tol: float, options: dict | None, warm: Any) -> QPSolution:
        settings = {"options": options} if options else {}
        return module.solve(prepared[0], tol=tol, solver=sub, **settings)

    def solution(self, prepared: Any, raw: QPSolution) -> QPSolution:
        return prepared[1].solution(raw)

    def polish(self, prepared: Any, raw: QPSolution, tol: float) -> QPSolution | None:
        # iterative answers stop at a tolerance: solve their active set exactly and keep that
        # when its certificate is at least as good. Small residuals do not mean accurate
        # velocities on ill-conditioned impacts (a 10⁵-ball chain passes at 1e-9 with
        # velocities off by 1e-6), so this is always tried.
        return polish(prepared[0], raw)

    def failure(self, program: QuadraticProgram, log: list[str]) -> Exception:
        if program.nonnegative and not lcp_feasible(normalize(program)[0]):
            return NoSolutionError("the LCP 0 ≤ Λ ⟂ GΛ + q ≥ 0 has no feasible point, so the "
                                   "law has no solution for this pre-impact velocity")
        return CertificateError("no backend met the certificate: " + "; ".join(log))


def lcp_feasible(qp: QuadraticProgram) -> bool:
    """For the impulse form: is there x ≥ 0 with Px + c ≥ 0? (For PSD P: solvable iff so;
    a positive definite P always is, decided by its Cholesky factor before any tolerance of
    a linear-programming solver can say otherwise: docs/theory.md §3.)"""
    if positive_definite(qp.P):
        return True
    res = linprog(np.zeros(qp.n_vars), A_ub=-qp.P, b_ub=qp.c, bounds=(0, None), method="highs")
    return bool(res.status == 0)


def positive_definite(P: Any) -> bool:
    """Whether the symmetric matrix P (dense or sparse) is positive definite: its Cholesky
    factor (dense), or its LDLᵀ's pivots all positive (sparse, :func:`symmetric_ldl`)."""
    if not sp.issparse(P):
        try:
            np.linalg.cholesky(np.asarray(P))
        except np.linalg.LinAlgError:
            return False
        return True
    try:
        return symmetric_ldl(P)[1]
    except RuntimeError:  # exactly singular
        return False


class ConeKind:
    """Cone programs: a backend's ``solve_cone``, retried a hundred times tighter."""

    def prepare(self, entry: Backend, program: Any) -> Any:
        return program

    def tolerances(self, entry: Backend, tol: float) -> tuple[float, ...]:
        return (tol, tol * 1e-2)

    def run(self, module: ModuleType, entry: Backend, sub: str | None, prepared: Any,
            tol: float, options: dict | None, warm: Any) -> Any:
        return module.solve_cone(prepared, tol=tol, solver=sub, options=options)

    def solution(self, prepared: Any, raw: Any) -> Any:
        return raw

    def polish(self, prepared: Any, raw: Any, tol: float) -> None:
        return None

    def failure(self, program: Any, log: list[str]) -> Exception:
        return CertificateError("no backend certified the cone program: " + "; ".join(log))


class FrictionKind:
    """Local frictional contact problems: a friction method's ``solve_friction`` once, at the
    tolerance, from the best answer so far (each method returns r projected onto the cones),
    finished by Newton when the method leaves that to the loop and is short of tol/2."""

    def __init__(self) -> None:
        self._data: FrictionData | None = None

    def prepare(self, entry: Backend, program: Any) -> FrictionData:
        if self._data is None or self._data.program is not program:
            self._data = FrictionData(program)
        return self._data

    def tolerances(self, entry: Backend, tol: float) -> tuple[float, ...]:
        return (tol,)

    def run(self, module: ModuleType, entry: Backend, sub: str | None, prepared: FrictionData,
            tol: float, options: dict | None, warm: FrictionSolution | None) -> FrictionSolution:
        start = None if warm is None else warm.r  # None: the method's own start, r = 0
        return module.solve_friction(prepared, start, tol=tol, method=entry.name)

    def solution(self, prepared: FrictionData, raw: FrictionSolution) -> FrictionSolution:
        return raw

    def polish(self, prepared: FrictionData, raw: FrictionSolution,
               tol: float) -> FrictionSolution | None:
        if not raw.polish_steps or prepared.error(raw.r) <= 0.5 * tol:
            return None
        r, steps, _ = newton(prepared, raw.r, tol, max_steps=raw.polish_steps)
        return FrictionSolution(project_cones(r, prepared.mu, prepared.d),
                                raw.iterations + steps, raw.backend)

    def failure(self, program: Any, log: list[str]) -> Exception:
        return CertificateError("no method certified the frictional contact problem: "
                                + "; ".join(log))


def kind_of(form: str) -> QPKind | ConeKind | FrictionKind:
    """A fresh kind for programs of ``form`` (the friction kind keeps state for one solve)."""
    if form == CONE:
        return ConeKind()
    if form == FRICTION:
        return FrictionKind()
    return QPKind()
