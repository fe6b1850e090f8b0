"""Which route answers: the one decision :func:`impactqp.solve`, :func:`impactqp.solve_batch`,
:func:`impactqp.solve_friction` and :func:`impactqp.simulate` share (docs/theory.md §9).

The entry points validate their input with :func:`validate` and ask :func:`plan` for a
:class:`Route`: the units an impact is solved in, the collapse of its parallel contacts,
the path that answers, and how the rows of a batch or the steps of a Moreau–Jean run are
taken. Every choice reads what the law declares (``law.family``, ``law.frictional``,
``law.restitution_per_contact``, ``law.homogeneous``, ``law.forms``; docs/theory.md §9),
never its class. The paths of one impact:

``"compiled"``
    a dense impact of a law of a compiled family (Moreau's, local Newton's, Frémond's law),
    solved and certified in one compiled call (:mod:`impactqp.laws.small`; a batch runs it
    row by row);
``"closed_form"``
    a law evaluated in closed form (the sector and reflection laws, LZB);
``"programs"``
    a law's quadratic programs, tried form by form on the registry's backends.

A compiled answer that misses its certificate falls through to the programs, so the route
only says where to start. A local frictional contact problem (:func:`plan_friction`) has
one path, the registry's friction methods (form ``"friction"``), and its route says in which
units it is posed (docs/theory.md §15).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, NamedTuple

from ..base.arrays import check_tol
from ..base.checks import UNIT_RANGE
from ..errors import InputError
from ..model.friction import ContactUnits, FrictionContactProblem
from ..model.problem import ImpactProblem
from ..qp import backends
from ..qp.backends import FORMS, FRICTION
from ..qp.certified import Finish, Plan
from ..qp.certified import plan as plan_programs
from . import chain_rows, parallel, small
from .base import FAMILIES, ImpactLaw

FORM_CHOICES = ("auto",) + FORMS
ROUTES = ("compiled", "closed_form", "programs")
"""The paths of one impact."""
BATCH_PATHS = ("chain", "compiled", "closed_form", "programs")
"""The paths of the rows of a batch: the chain's columns (:mod:`.chain_rows`), the compiled
impact row by row, the closed form on all rows, the programs (a vectorised fast-path
backend where one takes them, else row by row through :func:`impactqp.solve`)."""
LOOPS = ("compiled", "python", "friction-compiled", "friction")
"""The loops of a Moreau–Jean run (docs/theory.md §14, §17)."""
MODES = ("single", "batch", "run", "friction")

TRIVIAL = "none"
"""The backend of the answer u⁺ = u⁻, Λ = 0 of an impact without contact or with u⁻ = 0
(:func:`impactqp.solve` reports it, and takes it back, refusing it for any other impact)."""

MAX_COMPILED_LOOP = 400
"""Most degrees of freedom and most contact columns a compiled Moreau–Jean loop takes (it
holds Ŵ⁻¹, Ŵ⁻¹H and HᵀŴ⁻¹H dense)."""


@dataclass(frozen=True, slots=True)
class Route:
    """How an answer is computed, decided once by :func:`plan` (docs/theory.md §9).

    Attributes
    ----------
    mode : {"single", "batch", "run", "friction"}
        One impact, the rows of a batch, a Moreau–Jean run, or a local frictional contact
        problem (:func:`plan_friction`).
    path : str
        Where the answer starts: one of :data:`ROUTES` (one impact), :data:`BATCH_PATHS`
        (a batch), :data:`LOOPS` (a run) or ``"friction"`` (the registry's friction
        methods).
    scale : float
        Units: the impact is solved with u⁻ divided by ``scale`` and the answer scaled back
        (a homogeneous law whose velocities lie outside the range worked in as given,
        docs/theory.md §8); 1.0 solves it as given.
    groups : parallel.Groups or None
        The groups of parallel contacts the impact is solved collapsed by
        (:mod:`.parallel`, docs/theory.md §1); None solves it as it is.
    units : ContactUnits or None
        Units of a frictional problem: it is solved as ``units.problem`` (in its contacts'
        units, docs/theory.md §15) and each answer scaled back; None solves it as given.
    programs : Plan or None
        The registry's plan of a frictional problem: the friction methods tried in order on
        the problem as posed, and how each answer is finished.
    """

    mode: str
    path: str
    scale: float = 1.0
    groups: parallel.Groups | None = None
    units: ContactUnits | None = None
    programs: Plan | None = None


_SINGLE = {path: Route("single", path) for path in ROUTES}
"""The routes of impacts solved in their units and uncollapsed, formed once (no allocation
on the way of a small impact)."""


class Stepping(NamedTuple):
    """What a Moreau–Jean run adds to the planning of its impacts.

    Attributes
    ----------
    force_compilable : bool
        The force is constant or linear (a compiled loop evaluates it).
    compiled : bool or None
        The caller's choice of a compiled loop (True), the Python loop (False), or None for
        the rule's.
    """

    force_compilable: bool
    compiled: bool | None = None


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
    if backend != TRIVIAL and (law.forms or backend != law.closed_form_backend):
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


def _path(problem: ImpactProblem, law: ImpactLaw, backend: str, form: str = "auto") -> str:
    """Where the answer of ``law`` on ``problem`` starts (one of :data:`ROUTES`)."""
    if small.applies(problem, law, backend, form):
        return "compiled"
    return "programs" if law.forms else "closed_form"


def plan(problem: ImpactProblem, law: ImpactLaw, backend: str = "auto", form: str = "auto",
         *, mode: str = "single", stepping: Stepping | None = None) -> Route:
    """The :class:`Route` of ``law`` on ``problem`` (validated by :func:`validate`).

    Parameters
    ----------
    problem : ImpactProblem
        The impact (``"single"``), the structure of a batch's rows, or the system's
        structure for a run (u⁻ unused then).
    law : ImpactLaw
    backend, form : str
        As given to the entry point (for a frictional run: the method of its local problem).
    mode : {"single", "batch", "run"}
        One impact (units, collapse, path), the rows of a batch (their path; a row the path
        leaves goes through :func:`impactqp.solve`, which plans its own route), or the loop
        of a Moreau–Jean run.
    stepping : Stepping, optional
        Required with ``mode="run"``.

    Raises
    ------
    InputError
        ``stepping.compiled`` True for a run no compiled loop takes.
    """
    if mode == "single":
        scale = problem.peak_minus
        if law.homogeneous and scale > 0 and not UNIT_RANGE[0] <= scale <= UNIT_RANGE[1]:
            return Route(mode, _path(problem, law, backend, form), scale=scale)
        groups = parallel.collapsible(problem, law)
        if groups is not None:
            return Route(mode, _path(problem, law, backend, form), groups=groups)
        return _SINGLE[_path(problem, law, backend, form)]
    if mode == "batch":
        if backend in ("auto", "isotonic") and chain_rows.suits(problem, law):
            return Route(mode, "chain")
        return Route(mode, _path(problem, law, backend, form))
    if mode != "run" or stepping is None:
        raise InputError(f"mode must be one of {MODES} (with stepping for a run), got {mode!r}")
    return Route(mode, _loop(problem, law, backend, stepping))


def plan_friction(problem: FrictionContactProblem, backend: str,
                  finish: Callable[[ContactUnits | None], Finish]) -> Route:
    """The :class:`Route` of a local frictional contact problem (mode and path
    ``"friction"``): its units (the problem in its contacts' units,
    :meth:`~impactqp.FrictionContactProblem.in_contact_units`, unless it is already in them)
    and the registry's plan of the friction methods on the problem so posed (``"auto"``: the
    registry's order; a named method alone), whose answers ``finish(units)`` finishes
    (``units`` None: the problem is posed as given).

    Raises
    ------
    UnknownBackendError
        Unknown or uninstalled backend.
    BackendUnsuitableError
        A named backend that does not solve this frictional problem (the message says why).
    OutOfRangeError
        Floats cannot pose the problem in its contacts' units.
    """
    units = problem.in_contact_units()
    posed = units.problem
    if posed is problem:
        units = None
    return Route("friction", "friction", units=units,
                 programs=plan_programs(FRICTION, posed, finish(units), backend))


def loop_fits(problem: ImpactProblem, backend: str, stepping: Stepping) -> bool:
    """Whether a compiled Moreau–Jean loop takes a run on ``problem``'s structure, whatever
    the law: ``backend="auto"``, a constant or linear force and a dense system with at least
    one contact column and at most :data:`MAX_COMPILED_LOOP` degrees of freedom and contact
    columns."""
    st = problem.structure
    return (backend == "auto" and stepping.force_compilable and not st.sparse
            and 0 < problem.n_impulses <= MAX_COMPILED_LOOP and st.n <= MAX_COMPILED_LOOP)


def _loop(problem: ImpactProblem, law: ImpactLaw, backend: str, stepping: Stepping) -> str:
    """The loop of a Moreau–Jean run: a compiled loop for a frictional law or a law of a
    compiled family where :func:`loop_fits`, else the Python loop."""
    fits = (law.frictional or law.family in FAMILIES) and loop_fits(problem, backend, stepping)
    use = fits if stepping.compiled is None else stepping.compiled
    if use and not fits:
        what = "frictional loop" if law.frictional else "loop"
        raise InputError(f"compiled=True: the compiled {what} does not take this run (a "
                         "law, a callable force, a backend other than 'auto', a sparse or a "
                         "larger system)")
    if law.frictional:
        return "friction-compiled" if use else "friction"
    return "compiled" if use else "python"
