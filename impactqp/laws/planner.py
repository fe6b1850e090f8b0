"""Which route answers an impact: the one decision :func:`impactqp.solve` and
:func:`impactqp.solve_batch` share (docs/theory.md §9).

Both entry points validate their input with :func:`validate` and ask :func:`route` how the
law is evaluated on the problem:

``"compiled"``
    a dense impact of Moreau's, local Newton's or Frémond's law, solved and certified in one
    compiled call (:mod:`impactqp.laws.small`; a batch runs it row by row);
``"closed_form"``
    a law evaluated in closed form (the sector and reflection laws, LZB);
``"programs"``
    a law's quadratic programs, tried form by form on the registry's backends.

A compiled answer that misses its certificate falls through to the programs, so the route
only says where to start.
"""

from __future__ import annotations

from typing import Any

from ..base.arrays import check_tol
from ..errors import InputError
from ..model.problem import ImpactProblem
from ..qp import backends
from ..qp.backends import FORMS
from . import small
from .base import ImpactLaw

FORM_CHOICES = ("auto",) + FORMS
ROUTES = ("compiled", "closed_form", "programs")


def check_problem(problem: Any) -> ImpactProblem:
    """``problem`` itself, or InputError when it is not an ImpactProblem."""
    if not isinstance(problem, ImpactProblem):
        raise InputError(f"problem must be an ImpactProblem (built by iq.ImpactProblem, "
                         f"iq.chain, iq.newtons_cradle, ...), got {type(problem).__name__}")
    return problem


def check_law(law: Any) -> ImpactLaw:
    """``law`` itself, or InputError when it is not an impact law object."""
    if ImpactLaw not in type(law).__mro__:  # isinstance, without the ABC machinery
        raise InputError(f"law must be an impact law object such as iq.Moreau(0.5), "
                         f"iq.Newton(e), iq.Fremond(E) or iq.SectorLaw(), got "
                         f"{type(law).__name__}")
    return law


def check_backend(backend: Any) -> str:
    """``backend`` when it is ``"auto"`` or a registered name, else UnknownBackendError."""
    if backend != "auto":
        backends.parse_backend(backend)
    return backend


def check_form(law: ImpactLaw, form: Any) -> str:
    """``form`` when it is "auto" or a form ``law`` has, else InputError."""
    if form not in FORM_CHOICES:
        raise InputError(f"form must be one of {FORM_CHOICES}, got {form!r}")
    if form != "auto" and form not in law.forms:
        has = ", ".join(law.forms) if law.forms else "none: it is evaluated in closed form"
        raise InputError(f"{law.title} has no {form} form (forms: {has})")
    return form


def validate(problem: Any, law: Any, backend: Any, form: Any, tol: Any) -> float:
    """Every check an entry point makes before solving; returns the validated ``tol``.

    Raises
    ------
    InputError, UnknownBackendError
        Not a problem or not a law, an unknown backend, a form the law has not got, a bad
        tolerance, or coefficients that do not fit the problem (named).
    """
    check_problem(problem)
    check_law(law)
    if law.forms or backend != law.closed_form_backend:
        check_backend(backend)
    check_form(law, form)
    tol = check_tol(tol)
    if problem.structure.contact_dim != 1:
        check_friction(problem, law)
    law.check(problem)
    return tol


def check_friction(problem: ImpactProblem, law: ImpactLaw) -> None:
    """InputError when ``problem`` has frictional contacts (``contact_dim`` > 1) and ``law``
    is not a frictional law (docs/theory.md §16): the message says what to use instead."""
    if problem.contact_dim > 1 and not law.frictional:
        raise InputError(f"{law.title} is a frictionless law but the problem has frictional "
                         f"contacts (contact_dim = {problem.contact_dim}): use "
                         "iq.Coulomb(mu, restitution), or apply the law to "
                         "problem.normal_problem(), the frictionless problem of the normal "
                         "columns")


def route(problem: ImpactProblem, law: ImpactLaw, backend: str, form: str = "auto") -> str:
    """Where the answer of ``law`` on ``problem`` starts (one of :data:`ROUTES`)."""
    if small.applies(problem, law, backend, form):
        return "compiled"
    return "programs" if law.forms else "closed_form"
