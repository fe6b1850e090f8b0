"""The one solve pipeline: validation → fast path → backend registry → polish → certificate →
result (docs/theory.md §8, §9).

Every impact law, every backend and every public wrapper (:func:`impactqp.moreau`, …) goes
through :func:`solve`; nothing else decides which backend runs or whether an answer is good
enough to return.
"""

from __future__ import annotations

import logging
import time
from functools import partial

import numpy as np

from ..base.checks import DEFAULT_TOL
from ..base.log import verbosity
from ..errors import (
    BackendUnsuitableError,
    CertificateError,
    NoSolutionError,
    OutOfRangeError,
)
from ..model.problem import ImpactProblem
from ..qp import backends
from ..qp.certified import FAST_PATHS, solve_in_forms
from ..qp.program import QPSolution
from . import parallel, small
from .base import Answer, ImpactLaw
from .planner import TRIVIAL, plan, validate
from .result import ImpactResult

LOG = logging.getLogger(__name__)

FALLBACK_LIMIT = 10_000
"""Most unknowns (n_dof) on which ``"auto"`` still tries general solvers after an exact fast
path's answer failed its certificate. That answer is exact, so its failure means a defect (in
the path or in the certificate), not a hard impact; above this size the general solvers take
minutes on what they would then be asked, so the solve stops at once with the fast path's
residuals."""


class _ExactPathFailed(Exception):
    """Leaves the fallback loop from a stage's finish; re-raised as CertificateError."""


def _fail_fast(problem: ImpactProblem, law: ImpactLaw, solution: QPSolution, cert,
               backend: str) -> None:
    """Raise :class:`_ExactPathFailed` when an exact fast path's answer on more than
    :data:`FALLBACK_LIMIT` unknowns fails its certificate under ``"auto"``."""
    if cert.ok or backend != "auto" or problem.n_dof <= FALLBACK_LIMIT:
        return
    if solution.backend.split("+")[0] not in FAST_PATHS:
        return
    name, value = cert.worst
    raise _ExactPathFailed(
        f"{law.title}: the exact {solution.backend} answer on {problem.n_dof} unknowns failed "
        f"its certificate ({name} = {value:.1e}, tol {cert.tol:.0e}); general solvers are "
        f"not tried above {FALLBACK_LIMIT} unknowns after an exact path failed")


def _result(problem: ImpactProblem, law: ImpactLaw, answer: Answer, backend: str, cert,
            start: float, *, form: str | None = None,
            attempts: list[str] | None = None) -> ImpactResult:
    return ImpactResult(problem, law.name, law.coefficients_for(problem), answer.u_plus,
                        answer.impulses, backend, cert, form=form, z=answer.z,
                        attempts=attempts, impact_law=law,
                        solve_time=time.perf_counter() - start)


def _trivial(problem: ImpactProblem) -> Answer:
    """No contact, or u⁻ = 0: u⁺ = u⁻ and Λ = 0, which solves every law of docs/theory.md §3
    exactly (γ⁻ = 0); a law with other data (a time-stepping law's previous velocity) may
    reject it, and its certificate decides."""
    u = problem.u_minus.copy()
    return Answer(u, np.zeros(problem.n_impulses), u.copy())


def solve(problem: ImpactProblem, law: ImpactLaw, backend: str = "auto", *,
          form: str = "auto", tol: float = DEFAULT_TOL, options: dict | None = None,
          verbose: bool | int = False) -> ImpactResult:
    """Solve one impact with any impact law and return a certified result.

    Parameters
    ----------
    problem : ImpactProblem
        M, W and u⁻.
    law : ImpactLaw
        ``iq.Moreau(eps)``, ``iq.Newton(e)``, ``iq.Fremond(E)``, ``iq.SectorLaw()``,
        ``iq.ReflectionLaw()`` or any subclass of :class:`impactqp.ImpactLaw`.
    backend : str
        ``"auto"`` (exact fast paths first, then QP solvers, falling back on failure; for
        Coulomb's law the friction methods in the registry's order) or a registered backend
        that serves the law's program (:func:`impactqp.available_backends`), tried alone;
        a law evaluated in closed form also takes its ``closed_form_backend``, and
        ``"none"`` asks for u⁺ = u⁻, Λ = 0 (an impact without contact or with u⁻ = 0). The
        result's ``backend`` is always a name this call takes back.
    form : {"auto", "velocity", "impulse"}
        Which program to solve, for laws that have several (they give the same u⁺).
    tol : float
        Tolerance of the recomputed certificate, in (0, 1).
    options : dict, optional
        Settings passed to the named backend's solver, on top of impactqp's tolerances:
        Clarabel's ``DefaultSettings`` attributes, OSQP's setup settings, keywords of cvxpy's
        ``Problem.solve`` or of the qpsolvers solver (``iq.available_backends()`` says what
        each takes; the exact backends take none). The certificate still decides.
    verbose : bool or {0, 1, 2}
        Print impactqp's log of this solve on stderr: True or 1 refusals and fallbacks, 2
        also every backend attempt and certificate (the ``"impactqp"`` logger, see
        :mod:`!impactqp.base.log`).

    Returns
    -------
    ImpactResult
        Only when its certificate passes; ``result.admissible`` says separately whether u⁺
        is physically admissible (in S).

    Raises
    ------
    InputError
        Not a problem or not a law, bad ``form`` or ``tol``, coefficients that do not fit the
        problem (all ``ValueError`` subclasses naming the argument).
    UnknownBackendError
        A backend impactqp does not know or that is not installed.
    BackendUnsuitableError
        A named backend that cannot take this law, form or problem (the message says why).
    NoSolutionError
        The law has no solution for this u⁻ (never for laws that always have one).
    CertificateError
        No backend produced an answer that passes the certificate.
    """
    if backend == "auto" and form == "auto" and options is None and not verbose:
        result = small.first_try(problem, law, tol)  # the compiled path, planned in short
        if result is not None:
            return result
    if verbose:
        with verbosity(verbose):
            return solve(problem, law, backend, form=form, tol=tol, options=options)
    start = time.perf_counter()
    tol = validate(problem, law, backend, form, tol)
    if backend == "auto":  # a law may name the backend its own "auto" means (Coulomb's method)
        backend = getattr(law, "default_backend", "auto")
    if options is not None:
        options = backends.check_options(backend, options)
    planned = plan(problem, law, backend, form)  # units, collapse and path, in one Route
    if planned.scale != 1.0:
        return _rescaled(problem, law, planned.scale, backend, form, tol, options, start)
    if planned.groups is not None:
        return _collapsed(problem, law, planned.groups, backend, form, tol, start, options)
    way = planned.path
    if way == "compiled":
        result = small.solve_small(problem, law, tol, start, backend, form)
        if result is not None:
            return result
        LOG.info("%s: the compiled path declined (certificate not met), trying the general "
                 "path", law.title)
    if problem.n_contacts == 0 or not problem.u_minus.any():
        answer = _trivial(problem)
        cert = law.certificate(problem, answer, tol)
        if cert.ok:  # the shortcut answers only when the law's own certificate passes
            return _result(problem, law, answer, TRIVIAL, cert, start,
                           attempts=["no contact or u⁻ = 0: u⁺ = u⁻, Λ = 0"])
        if problem.n_contacts == 0:
            raise CertificateError(f"{law.title} without contacts: u⁺ = u⁻ fails its "
                                   f"certificate, {cert.summary()}")
    if backend == TRIVIAL:
        raise BackendUnsuitableError(f"backend={TRIVIAL!r} answers u⁺ = u⁻, Λ = 0, an impact "
                                     f"without contact or with u⁻ = 0 that {law.title}'s "
                                     "certificate passes; this one is not: pass "
                                     "backend='auto'")
    if way == "closed_form":
        return _closed_form(problem, law, backend, tol, start)

    forms = (form,) if form != "auto" else law.preferred_forms(problem)

    def stage(f: str):
        def finish(solution: QPSolution):
            answer = law.recover(problem, f, solution)
            cert = law.certificate(problem, answer, tol)
            _fail_fast(problem, law, solution, cert, backend)
            return answer, cert
        return f, partial(law.program, problem, f), finish

    try:
        out = solve_in_forms([stage(f) for f in forms], backend, options)
    except _ExactPathFailed as exc:
        raise CertificateError(str(exc)) from None
    except NoSolutionError as exc:
        if law.always_solvable:  # a solution exists: failing to find it is the solvers'
            raise CertificateError(f"{law.title} has a solution for every u⁻, but no "
                                   f"backend certified one: {exc}") from exc
        raise
    return _result(problem, law, out.answer, out.backend, out.checks, start, form=out.form,
                   attempts=out.attempts)


def _rescaled(problem: ImpactProblem, law: ImpactLaw, scale: float, backend: str, form: str,
              tol: float, options: dict | None, start: float) -> ImpactResult:
    """The impact solved with u⁻ divided by ``scale`` (order one) and the answer scaled back:
    for a homogeneous law u⁺ and Λ scale with u⁻ and the dimensionless certificate does not
    change (docs/theory.md §8), while products of velocities 1e±160 would leave the floats."""
    unit = solve(problem.with_u_minus(problem.u_minus / scale), law, backend, form=form,
                 tol=tol, options=options)
    with np.errstate(over="ignore"):
        u_plus, impulses = unit.u_plus * scale, unit.impulses * scale
    if not (np.isfinite(u_plus).all() and np.isfinite(impulses).all()):
        raise OutOfRangeError(f"{law.title}: u⁺ or Λ ({max(np.abs(unit.u_plus).max(), 1.0):.3g}"
                              f" × {scale:.3g} in the problem's units) overflows floats")
    if tol * scale < np.finfo(float).smallest_subnormal:  # u⁺ is measured against scale
        raise OutOfRangeError(f"{law.title}: u⁺ (× {scale:.3g} in the problem's units) lands "
                              "among the subnormal floats, whose spacing is beyond the "
                              f"tolerance {tol:.0e} of the answer (docs/theory.md §8)")
    return _result(problem, law, Answer(u_plus, impulses, None), unit.backend,
                   unit.certificate, start, form=unit.form,
                   attempts=[f"solved in units of u⁻/{scale:.3g}", *unit.attempts])


def _collapsed(problem: ImpactProblem, law: ImpactLaw, groups: parallel.Groups, backend: str,
               form: str, tol: float, start: float, options: dict | None) -> ImpactResult:
    """The impact with its parallel contacts collapsed (:mod:`.parallel`), its impulses split
    back and certified on the original problem."""
    reduced = solve(ImpactProblem.from_structure(groups.reduced, problem.u_minus),
                    parallel.reduced_law(law, groups), backend, form=form, tol=tol,
                    options=options)
    answer = parallel.expand(Answer(reduced.u_plus, reduced.impulses, reduced.z), groups)
    cert = law.certificate(problem, answer, tol)
    if not cert.ok:
        raise CertificateError(f"{law.title}: the answer of the collapsed impact fails the "
                               f"certificate of the original one, {cert.summary()}")
    note = (f"{problem.n_contacts} contacts in {groups.representative.size} groups of "
            "parallel ones: solved collapsed, impulses split back")
    LOG.info(note)
    return _result(problem, law, answer, reduced.backend, cert, start, form=reduced.form,
                   attempts=[note, *reduced.attempts])


def _closed_form(problem: ImpactProblem, law: ImpactLaw, backend: str, tol: float,
                 start: float) -> ImpactResult:
    if backend not in ("auto", law.closed_form_backend):
        raise BackendUnsuitableError(f"{law.title} is evaluated in closed form; pass "
                                     f"backend='auto', not {backend!r}")
    answer = law.answer_of(problem, law.closed_form(problem))
    cert = law.certificate(problem, answer, tol)
    if not cert.ok:
        raise CertificateError(f"{law.title}: certificate failed, {cert.summary()}")
    if LOG.isEnabledFor(logging.DEBUG):
        LOG.debug("%s in closed form: certificate %s", law.title, cert.summary())
    return _result(problem, law, answer, law.closed_form_backend, cert, start,
                   attempts=[f"{law.closed_form_backend}: certified"])
