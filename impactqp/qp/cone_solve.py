"""Solve a cone program through the backend registry and certify the answer
(docs/theory.md §9).

A named backend must list the ``"cone"`` form (:data:`~impactqp.qp.backends.CONE`); any
other refuses by name and says which backends take cones. ``"auto"`` tries those backends
in :data:`~impactqp.qp.backends.AUTO_ORDER`. The certified loop
(:func:`~impactqp.qp.certified.solve_certified`) runs each at the requested tolerance and once
more a hundred times tighter; an answer is returned only when its certificate, recomputed by
:meth:`~impactqp.qp.cones.ConeProgram.certificate`, is within ``accept``.
"""

from __future__ import annotations

import dataclasses

from ..base.arrays import check_tol
from ..base.checks import NamedChecks
from ..errors import InputError
from . import backends
from .certified import plan, solve_certified
from .cones import ConeProgram, ConeSolution

ACCEPT = 1e-8
"""Default tolerance of a cone answer's certificate (relative residuals, docs/theory.md
§9)."""


def solve_cone(program: ConeProgram, backend: str = "clarabel", *, tol: float = 1e-10,
               accept: float = ACCEPT, options: dict | None = None) -> ConeSolution:
    """Solve ``program`` with ``backend`` and return the answer with its certificate.

    Parameters
    ----------
    program : ConeProgram
    backend : str
        A backend that takes cones (``"clarabel"``, ``"cvxpy"``, ``"cvxpy:ECOS"``, ...) or
        ``"auto"`` (each of them in registry order until one is certified).
    tol : float
        The solver's stopping tolerance (then a hundred times tighter on a retry).
    accept : float
        Tolerance of the recomputed certificate.
    options : dict, optional
        Settings of the named backend's solver (as for :func:`impactqp.solve`).

    Returns
    -------
    ConeSolution
        With ``checks`` set and passing.

    Raises
    ------
    UnknownBackendError
        Unknown or uninstalled backend.
    BackendUnsuitableError
        A backend that does not take cone programs (the message names those that do).
    CertificateError
        No attempt gave an answer within ``accept``; the message gives each failure.
    """
    if not isinstance(program, ConeProgram):
        raise InputError(f"program must be a ConeProgram, got {type(program).__name__}")
    tol, accept = check_tol(tol), check_tol(accept, "accept")
    options = backends.check_options(backend, options)

    def finish(sol: ConeSolution) -> tuple[ConeSolution, NamedChecks]:
        checks = program.certificate(sol.x, sol.z, accept)
        return dataclasses.replace(sol, checks=checks), checks

    planned = plan(backends.CONE, program, finish, backend)
    return solve_certified(planned, named=backend != "auto", tol=tol,
                           options=options).answer
