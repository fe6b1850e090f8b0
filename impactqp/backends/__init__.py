"""QP backends: one module per solver, registered by name, loaded on first use.

A backend is a function ``solve(qp, *, tol, solver=None) -> QPSolution`` for the program
``min ½xᵀPx + cᵀx s.t. Ax ≥ b`` (:mod:`impactqp.program`). Names:

* ``"exact"`` – active-set enumeration (the reference; up to ~14 constraints);
* ``"nnls"`` – exact non-negative least squares on the impulse form (scipy);
* ``"clarabel"`` – Clarabel's own Python API;
* ``"osqp"`` – OSQP;
* ``"cvxpy"`` or ``"cvxpy:SOLVER"`` – any solver installed for cvxpy;
* ``"qpsolvers:NAME"`` – any solver installed for qpsolvers.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

from ..errors import UnknownBackendError
from ..program import QPSolution, QuadraticProgram

BackendFn = Callable[..., QPSolution]

#: backend name -> (module, extra that provides it)
_MODULES: dict[str, tuple[str, str]] = {
    "exact": ("exact", "impactqp"),
    "nnls": ("nnls_", "scipy"),
    "clarabel": ("clarabel_", "clarabel"),
    "osqp": ("osqp_", "osqp"),
    "cvxpy": ("cvxpy_", "cvxpy"),
    "qpsolvers": ("qpsolvers_", "qpsolvers"),
}

QP_BACKENDS = tuple(_MODULES)

#: how each solver (qpsolvers or cvxpy name, lower case) spells its stopping tolerances
TOLERANCE_OPTIONS: dict[str, tuple[str, ...]] = {
    "clarabel": ("tol_gap_abs", "tol_gap_rel", "tol_feas"),
    "osqp": ("eps_abs", "eps_rel"),
    "piqp": ("eps_abs", "eps_rel"),
    "proxqp": ("eps_abs", "eps_rel"),
    "scs": ("eps_abs", "eps_rel"),
    "ecos": ("abstol", "reltol", "feastol"),
}


def tolerance_options(solver: str | None, tol: float) -> dict[str, float]:
    """Keyword arguments that set every stopping tolerance of ``solver`` to ``tol``
    (empty for solvers without one, such as the active-set solver daqp)."""
    return {name: tol for name in TOLERANCE_OPTIONS.get((solver or "").lower(), ())}


def parse_backend(name: str) -> tuple[str, str | None]:
    """Split ``"family:solver"`` and check that the family exists.

    Raises
    ------
    UnknownBackendError
        For a name impactqp does not know.
    """
    if not isinstance(name, str):
        raise UnknownBackendError(f"backend must be a string, got {type(name).__name__}")
    family, _, sub = name.partition(":")
    family = family.strip().lower()
    if family not in _MODULES:
        raise UnknownBackendError(
            f"unknown backend {name!r}; choose one of 'auto', "
            + ", ".join(repr(k) for k in _MODULES) + " (or 'cvxpy:SOLVER', 'qpsolvers:NAME')")
    if sub and family not in ("cvxpy", "qpsolvers"):
        raise UnknownBackendError(f"backend {family!r} takes no sub-solver, got {name!r}")
    if family == "qpsolvers" and not sub:
        raise UnknownBackendError("backend 'qpsolvers' needs a solver name, e.g. 'qpsolvers:daqp'")
    return family, (sub or None)


def get_backend(name: str) -> tuple[BackendFn, str | None]:
    """Return the solve function of a backend and its sub-solver name."""
    family, sub = parse_backend(name)
    module_name, extra = _MODULES[family]
    try:
        module = importlib.import_module(f".{module_name}", __name__)
    except ImportError as exc:  # a missing optional solver must not break impactqp
        raise UnknownBackendError(f"backend {family!r} is not installed ({exc}); "
                                  f"install the {extra!r} package") from exc
    return module.solve, sub


def solve_qp(qp: QuadraticProgram, backend: str, *, tol: float = 1e-10) -> QPSolution:
    """Solve ``qp`` with the named backend (no certificate, no fallback)."""
    fn, sub = get_backend(backend)
    return fn(qp, tol=tol, solver=sub)
