"""``iq.derivative(problem, law)``: solve one impact and differentiate the law's map at the
certified answer (docs/theory.md §18–§20)."""

from __future__ import annotations

from typing import Any

from ..base.checks import DEFAULT_TOL
from ..laws.pipeline import solve
from .impact import KINK_TOL, ImpactDerivative


def derivative(problem: Any, law: Any, backend: str = "auto", *, tol: float = DEFAULT_TOL,
               kink_tol: float = KINK_TOL) -> ImpactDerivative:
    """The derivative of ``law``'s impact map at its certified answer on ``problem``:
    ``iq.solve(problem, law, backend, tol=tol).derivative(kink_tol=kink_tol)``.

    Parameters
    ----------
    problem : ImpactProblem
    law : ImpactLaw
    backend : str
        As for :func:`impactqp.solve` (the derivative does not depend on it).
    tol : float
        The solve's certificate tolerance, also the derivative certificate's.
    kink_tol : float
        Degeneracy tolerance (docs/theory.md §19).

    Returns
    -------
    ImpactDerivative
        ``status`` ``"smooth"``, ``"kink"`` or ``"unsupported"`` (a law without a
        ``derivative`` hook, named).
    """
    return solve(problem, law, backend, tol=tol).derivative(kink_tol=kink_tol)
