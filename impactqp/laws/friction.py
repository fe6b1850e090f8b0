"""Certified solutions of local frictional contact problems (docs/theory.md §15).

The friction methods are entries of the backend registry (form ``"friction"``,
:mod:`impactqp.qp.backends`): the compiled call of a few contacts (``"kernel"``), a short and a
long projected Gauss–Seidel (``"nsgs-short"``, ``"nsgs"``), Alart–Curnier's semismooth Newton
(``"newton"``, ``"newton-damped"``), the least-squares Newton on the natural map
(``"newton-lstsq"``) and a fixed point of second-order cone programs solved by Clarabel
(``"clarabel"``). :func:`solve_friction` runs them through the one certified loop
(:func:`impactqp.qp.certified.solve_certified`), which polishes by Newton where a method leaves
that to it; every answer is certified by :func:`impactqp.model.friction.certify_friction` and
none that fails is returned.
"""

from __future__ import annotations

import time

import numpy as np

from ..base.arrays import check_tol
from ..errors import InputError, OutOfRangeError
from ..model.friction import (
    ContactUnits,
    FrictionCertificate,
    FrictionContactProblem,
    certify_friction,
)
from ..qp import backends
from ..qp.certified import Outcome, plan, solve_certified
from ..qp.friction import FrictionSolution
from .result import FrictionResult

__all__ = ["FRICTION_BACKENDS", "FrictionResult", "solve_friction"]

FRICTION_BACKENDS = ("auto", *backends.serving(backends.FRICTION))
"""What ``backend=`` of :func:`solve_friction` takes: ``"auto"`` (the registry's
:data:`~impactqp.qp.backends.AUTO_ORDER`) or one friction method of the registry."""


def solve_friction(problem: FrictionContactProblem, *, backend: str = "auto",
                   tol: float = 1e-8) -> FrictionResult:
    """Solve u = W r + q, r_c ∈ K_μc ⟂ u_c + μ_c‖u_T,c‖e_n ∈ K*_μc with a certificate
    (docs/theory.md §15), in the problem's contacts' units
    (:meth:`~impactqp.FrictionContactProblem.in_contact_units`): r and u are scaled back and
    certified on the problem as given.

    Parameters
    ----------
    problem : FrictionContactProblem
    backend : str
        ``"auto"``: the friction methods in the registry's order (one compiled call for a
        few contacts, 100 NSGS sweeps then Newton, Newton from r = 0, the SOCP fixed point,
        the damped Newton, the least-squares Newton, a long NSGS; docs/theory.md §15), or one
        of them by name (:data:`FRICTION_BACKENDS`, ``iq.available_backends()``), tried
        alone. The result's ``backend`` is always one of these names.
    tol : float
        Tolerance of the certificate: ‖F‖/‖q‖ ≤ tol among others.

    Returns
    -------
    FrictionResult

    Raises
    ------
    UnknownBackendError
        A backend impactqp does not know.
    BackendUnsuitableError
        A backend that does not solve frictional problems, or not this one (the message says
        why).
    CertificateError
        No method reached the tolerance; the message gives each attempt.
    OutOfRangeError
        The answer is beyond what floats hold in the problem's units.
    """
    if not isinstance(problem, FrictionContactProblem):
        raise InputError(f"problem must be a FrictionContactProblem, got "
                         f"{type(problem).__name__}")
    tol = check_tol(tol)
    units = problem.in_contact_units()
    if units.problem is not problem:
        return _rescaled(problem, units, backend, tol)
    start = time.perf_counter()
    out = solve_local(problem, backend, tol)
    return _result(out, time.perf_counter() - start)


def solve_local(problem: FrictionContactProblem, backend: str, tol: float) -> Outcome:
    """The certified loop on ``problem``; its answer is the method's
    :class:`~impactqp.qp.friction.FrictionSolution` and u = W r + q."""

    def finish(sol: FrictionSolution) -> tuple[tuple[FrictionSolution, np.ndarray],
                                               FrictionCertificate]:
        u = problem.velocity(sol.r)
        return (sol, u), certify_friction(problem, sol.r, u, tol=tol)

    planned = plan(backends.FRICTION, problem, finish, backend)
    return solve_certified(planned, named=backend != "auto", tol=tol)


def _result(out: Outcome, seconds: float) -> FrictionResult:
    (sol, u), cert = out.answer, out.checks
    return FrictionResult(sol.r, u, cert.error, cert, sol.iterations, seconds, out.backend,
                          out.attempts)


def _rescaled(problem: FrictionContactProblem, units: ContactUnits, backend: str,
              tol: float) -> FrictionResult:
    """The problem solved in its contacts' units (W̃ = DWD, q̂ = 2⁻ᵏDq: the normal diagonal
    one and max|q̂ᵢ| within :data:`~impactqp.model.friction.QUANTITY_RANGE`), the answer
    scaled back (r = 2ᵏ r̂/s, u = 2ᵏ s∘û) and certified on the problem as given
    (docs/theory.md §15).

    Raises
    ------
    OutOfRangeError
        r or u is beyond the floats, or lands where floats hold it too coarsely for the
        certificate (the answer in contact units was certified).
    """
    start = time.perf_counter()
    found = solve_friction(units.problem, backend=backend, tol=tol)
    r, u = units.reaction(found.r), units.velocity(found.u)
    if not (np.isfinite(r).all() and np.isfinite(u).all()):
        raise OutOfRangeError("the reaction or velocity of this problem is beyond the floats "
                              f"(2^{units.k} times its answer in contact units)")
    cert = certify_friction(problem, r, u, tol=tol)
    if not cert.ok:  # certified in contact units: only the floats' range can lose it here
        raise OutOfRangeError("floats hold the reaction or velocity of this problem too "
                              f"coarsely for its certificate (2^{units.k} times its answer "
                              f"in contact units): {cert.summary()}")
    return FrictionResult(r, u, cert.error, cert, found.iterations,
                          time.perf_counter() - start, found.backend,
                          [f"solved in its contacts' units (2^{units.k})", *found.attempts])
