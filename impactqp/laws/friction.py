"""Certified solutions of local frictional contact problems (docs/theory.md §15).

The friction methods are entries of the backend registry (form ``"friction"``,
:mod:`impactqp.qp.backends`): the compiled call of a few contacts (``"kernel"``), a short and a
long projected Gauss–Seidel (``"nsgs-short"``, ``"nsgs"``), Alart–Curnier's semismooth Newton
(``"newton"``, ``"newton-damped"``), Newton with local repairs of where it stalls
(``"newton-repair"``, docs/theory.md §22), the least-squares Newton on the natural map
(``"newton-lstsq"``) and a fixed point of second-order cone programs solved by Clarabel
(``"clarabel"``). :func:`solve_friction` runs them through the one certified loop
(:func:`impactqp.qp.certified.solve_certified`), which polishes by Newton where a method leaves
that to it; every answer is certified by :func:`impactqp.model.friction.certify_friction` and
none that fails is returned.
"""

from __future__ import annotations

from collections.abc import Callable
from time import perf_counter

import numpy as np

from ..base.arrays import check_tol
from ..base.checks import FRICTION_TOL
from ..errors import CertificateError, InputError, OutOfRangeError
from ..model.friction import (
    ContactUnits,
    FrictionCertificate,
    FrictionContactProblem,
    certify_friction,
)
from ..qp import backends
from ..qp.certified import Outcome, solve_certified
from ..qp.friction import FrictionSolution
from .friction_small import solve_few
from .planner import plan_friction
from .result import FrictionResult

__all__ = ["FRICTION_BACKENDS", "FrictionResult", "solve_friction"]

FRICTION_BACKENDS = ("auto", *backends.serving(backends.FRICTION))
"""What ``backend=`` of :func:`solve_friction` takes: ``"auto"`` (the registry's
:data:`~impactqp.qp.backends.AUTO_ORDER`) or one friction method of the registry."""


def solve_friction(problem: FrictionContactProblem, *, backend: str = "auto",
                   tol: float = FRICTION_TOL) -> FrictionResult:
    """Solve u = W r + q, r_c ∈ K_μc ⟂ u_c + μ_c‖u_T,c‖e_n ∈ K*_μc with a certificate
    (docs/theory.md §15), in the problem's contacts' units
    (:meth:`~impactqp.FrictionContactProblem.in_contact_units`): r and u are scaled back and
    certified on the problem as given.

    Parameters
    ----------
    problem : FrictionContactProblem
    backend : str
        ``"auto"``: the friction methods in the registry's order (one compiled call for a
        few contacts, 100 NSGS sweeps then Newton, Newton from r = 0, the SOCP fixed point
        and Newton with local repairs (the repairs first from 1000 contacts on), the damped
        Newton, the least-squares Newton, a long NSGS; docs/theory.md §15, §22), or one
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
        No method reached the tolerance; the message gives each attempt, and the
        exception's ``best`` is the answer that came closest: a :class:`FrictionResult`
        with ``status == "not certified"``, its ABH ``error`` and its certificate (None
        when no method answered at all), ``attempts`` the attempts.
    OutOfRangeError
        The answer is beyond what floats hold in the problem's units.
    """
    if not isinstance(problem, FrictionContactProblem):
        raise InputError(f"problem must be a FrictionContactProblem, got "
                         f"{type(problem).__name__}")
    start = perf_counter()
    tol = check_tol(tol)
    if backend == "auto" or backend == "kernel":
        few = solve_few(problem, tol, start, backend == "auto")
        if few is not None:
            return few
    return _solve_general(problem, backend, tol, start)


def _solve_general(problem: FrictionContactProblem, backend: str, tol: float,
                   start: float) -> FrictionResult:
    """:func:`solve_friction` by the registry's plan, ``start`` the ``perf_counter()`` of
    the solve's start. Apart from :func:`solve_friction` so that its closure over
    ``problem`` and ``tol`` (cells, ~0.1 µs a call) is not made on the route of a few
    contacts."""
    # units and the registry's plan, in one Route
    route = plan_friction(problem, backend, lambda units: _finisher(problem, units, tol))
    note = () if route.units is None else (f"solved in its contacts' units (2^{route.units.k})",)
    try:
        out = solve_certified(route.programs, named=backend != "auto", tol=tol)
    except CertificateError as exc:
        if not isinstance(exc.best, Outcome):
            raise
        best = _result(exc.best, perf_counter() - start, note)
        raise CertificateError(f"{exc} (the best answer found, error {best.error:.2e}, is "
                               "the exception's .best)", best=best,
                               attempts=exc.attempts) from None
    return _result(out, perf_counter() - start, note)


def _finisher(problem: FrictionContactProblem, units: ContactUnits | None,
              tol: float) -> Callable[[FrictionSolution], tuple[tuple, FrictionCertificate]]:
    """What finishes a method's answer on ``problem`` or, with ``units``, on the same problem
    in its contacts' units (W̃ = DWD, q̂ = 2⁻ᵏDq: the normal diagonal one and max|q̂ᵢ| within
    :data:`~impactqp.model.friction.QUANTITY_RANGE`): the answer is scaled back
    (r = 2ᵏ r̂/s, u = 2ᵏ s∘û) and certified once, on the problem as given
    (:func:`_scaled_back`, docs/theory.md §15). It gives the method's
    :class:`~impactqp.qp.friction.FrictionSolution` with r and u = W r + q as given, and the
    certificate."""
    posed = problem if units is None else units.problem

    def finish(sol: FrictionSolution) -> tuple[tuple[FrictionSolution, np.ndarray,
                                                     np.ndarray], FrictionCertificate]:
        u = posed.velocity(sol.r)
        if units is None:
            return (sol, sol.r, u), certify_friction(problem, sol.r, u, tol=tol)
        r_given, u_given, cert = _scaled_back(problem, units, sol.r, u, tol)
        return (sol, r_given, u_given), cert

    return finish


def _result(out: Outcome, seconds: float, note: tuple[str, ...] = ()) -> FrictionResult:
    (sol, r, u), cert = out.answer, out.checks
    return FrictionResult(r, u, cert.error, cert, sol.iterations, seconds, out.backend,
                          [*note, *out.attempts])


def _scaled_back(problem: FrictionContactProblem, units: ContactUnits, r_unit: np.ndarray,
                 u_unit: np.ndarray,
                 tol: float) -> tuple[np.ndarray, np.ndarray, FrictionCertificate]:
    """r and u of the problem as given from an answer in contact units, with the certificate
    on the problem as given: the one certificate of the answer.

    Raises
    ------
    OutOfRangeError
        r or u is beyond the floats, or lands where floats hold it too coarsely for its
        certificate although the answer in contact units passes its own.
    """
    r, u = units.reaction(r_unit), units.velocity(u_unit)
    if not (np.isfinite(r).all() and np.isfinite(u).all()):
        raise OutOfRangeError("the reaction or velocity of this problem is beyond the floats "
                              f"(2^{units.k} times its answer in contact units)")
    cert = certify_friction(problem, r, u, tol=tol)
    if not cert.ok and certify_friction(units.problem, r_unit, u_unit, tol=tol).ok:
        raise OutOfRangeError("floats hold the reaction or velocity of this problem too "
                              f"coarsely for its certificate (2^{units.k} times its answer "
                              f"in contact units): {cert.summary()}")
    return r, u, cert
