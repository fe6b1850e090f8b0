"""Solve a cone program through the backend registry and certify the answer
(docs/theory.md §9).

A named backend must list the ``"cone"`` form (:data:`~impactqp.qp.backends.CONE`); any
other refuses by name and says which backends take cones. ``"auto"`` tries those backends
in registry order. Each is run at the requested tolerance and once more a hundred times
tighter; an answer is returned only when its certificate, recomputed by
:meth:`~impactqp.qp.cones.ConeProgram.certificate`, is within ``accept``.
"""

from __future__ import annotations

import dataclasses

from ..base.arrays import check_tol
from ..errors import (
    BackendUnsuitableError,
    CertificateError,
    InputError,
    SolverError,
    UnknownBackendError,
)
from . import backends
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
    names = backends.cone_backends() if backend == "auto" else (backend,)
    failures: list[str] = []
    for name in names:
        entry, sub = backends.parse_backend(name)
        reason = backends.unsuitable(entry, program, backends.CONE)
        if reason is not None:
            if backend != "auto":
                raise BackendUnsuitableError(reason)
            failures.append(reason)
            continue
        try:
            module = backends.load(entry)
        except UnknownBackendError as exc:
            if backend != "auto":
                raise
            failures.append(str(exc))
            continue
        for attempt in (tol, tol * 1e-2):
            try:
                sol = module.solve_cone(program, tol=attempt, solver=sub, options=options)
            except SolverError as exc:
                failures.append(f"{name} (tol {attempt:.0e}): {exc}")
                continue
            checks = program.certificate(sol.x, sol.z, accept)
            if checks.ok:
                return dataclasses.replace(sol, checks=checks)
            failures.append(f"{sol.backend} (tol {attempt:.0e}): certificate {checks.summary()}")
    raise CertificateError("no backend certified the cone program: " + "; ".join(failures))
