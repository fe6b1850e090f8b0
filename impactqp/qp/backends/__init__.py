"""The backend registry: every way impactqp can solve a program, exact paths included.

A backend is a module with ``solve(qp, *, tol, solver=None) -> QPSolution`` and, where it
serves only some programs, ``unsuitable(qp) -> str | None`` (why it cannot take ``qp``).
Backends that solve many right-hand sides at once also have ``solve_many``; backends that
take cone programs (:mod:`impactqp.qp.cones`) have ``solve_cone(program, *, tol, solver,
options) -> ConeSolution``; backends that take local frictional contact problems
(:mod:`impactqp.qp.friction`) have ``solve_friction(data, start, *, tol, method) ->
FrictionSolution`` and, where they serve only some, ``unsuitable_friction(program)``.
Backends know programs only (:mod:`impactqp.qp.program`), never impacts or laws
(docs/theory.md §9).

Each entry declares the program forms it serves (``"velocity"``: general ``Ax ≥ b``;
``"impulse"``: ``x ≥ 0``, an LCP; ``"cone"``: a :class:`~impactqp.qp.cones.ConeProgram`;
``"friction"``: u = W r + q, r ∈ K_μ ⟂ ũ ∈ K*_μ), whether its answers are exact (no polishing
needed), and what it is for; :data:`AUTO_ORDER` says in which order ``"auto"`` tries the
entries of the cone and friction forms.
:func:`available_backends` lists them with their install state; :data:`SOLVERS`
(:mod:`.solvers`) lists the solvers the families ``"cvxpy"`` and ``"qpsolvers"`` reach, with
the extra that installs each, and a sub-solver that is not installed is refused by name with
that extra (:func:`.solvers.missing_solver`); :func:`sub_solvers` says which are installed.
"""

from __future__ import annotations

import importlib
import importlib.util
from dataclasses import dataclass
from functools import cache
from types import ModuleType

from ...errors import BackendUnsuitableError, InputError, UnknownBackendError
from .solvers import SOLVERS

FORMS = ("velocity", "impulse")
"""The forms of quadratic programs (the ``form=`` of :func:`impactqp.solve`)."""

CONE = "cone"
"""The form of cone programs (:class:`~impactqp.qp.cones.ConeProgram`), served by the
entries that list it among their forms."""

FRICTION = "friction"
"""The form of local frictional contact problems (:mod:`impactqp.qp.friction`, e.g.
:class:`~impactqp.FrictionContactProblem`), served by the friction methods."""


@dataclass(frozen=True)
class Backend:
    """One registered backend.

    Attributes
    ----------
    name : str
        The name users pass (``"clarabel"``); families with sub-solvers take ``"name:SOLVER"``.
    module : str
        Module in this package that implements it.
    requires : str
        Python package that must be importable.
    install : str
        What to install when it is missing.
    forms : tuple of str
        Program forms served (see :data:`FORMS`, and :data:`CONE` for cone programs).
    exact : bool
        Answers are exact active-set solutions (never polished).
    serves : str
        One line on what it takes (sizes, structure).
    sub_solver : {"none", "optional"}
        Whether ``"name:SOLVER"`` is accepted.
    scale_free : bool
        Its answer does not depend on the units of the program (relative tolerances only),
        so it needs no normalization (docs/theory.md §9).
    options : str
        What ``options=`` of :func:`impactqp.solve` sets for it ("" when it takes none).
    """

    name: str
    module: str
    requires: str
    install: str
    forms: tuple[str, ...]
    exact: bool
    serves: str
    sub_solver: str = "none"
    scale_free: bool = False
    options: str = ""

    @property
    def installed(self) -> bool:
        return _importable(self.requires)


REGISTRY: dict[str, Backend] = {b.name: b for b in (
    Backend("kernel", "kernel", "numba", "numba", ("impulse", FRICTION), True,
            "compiled active-set search: dense impulse form, at most 400 contacts; friction: "
            "dense Newton and NSGS in one compiled call, at most 32 contacts",
            scale_free=True),
    Backend("isotonic", "isotonic", "scipy", "scipy", ("velocity",), True,
            "weighted isotonic regression: velocity form of 1-D chains, O(N)", scale_free=True),
    Backend("exact", "exact", "numpy", "numpy", FORMS, True,
            "active-set enumeration, at most 14 constraints: the reference"),
    Backend("nnls", "nnls_", "numba", "numba", ("impulse",), True,
            "compiled NNLS on the Cholesky-scaled impulse form: dense, at most 400 contacts"),
    Backend("clarabel", "clarabel_", "clarabel", "clarabel", FORMS + (CONE, FRICTION), False,
            "Clarabel's own API (interior point), sparse; friction: a fixed point of "
            "second-order cone programs, finished by Newton",
            options="attributes of clarabel.DefaultSettings (max_iter, tol_gap_abs, ...)"),
    Backend("osqp", "osqp_", "osqp", "osqp", FORMS, False, "OSQP (operator splitting), sparse",
            options="OSQP settings of its setup (max_iter, eps_abs, rho, ...)"),
    Backend("cvxpy", "cvxpy_", "cvxpy", "cvxpy-base (a dependency of impactqp; pip install "
            "'impactqp[solvers]' adds SCS, ECOS, HiGHS, PIQP and DAQP for it)",
            FORMS + (CONE,), False,
            "any solver installed for cvxpy ('cvxpy:SOLVER'; default Clarabel)",
            sub_solver="optional",
            options="keyword arguments of cvxpy's Problem.solve for the solver"),
    Backend("qpsolvers", "qpsolvers_", "qpsolvers", "qpsolvers (a dependency of impactqp; pip "
            "install 'impactqp[solvers]' adds daqp, piqp, quadprog, ecos, scs and highs for it)",
            FORMS, False,
            "any solver installed for qpsolvers ('qpsolvers:NAME', e.g. daqp, piqp, highs; "
            "'qpsolvers' alone: the best installed one for the program)",
            sub_solver="optional", options="keyword arguments of the qpsolvers solver"),
    Backend("nsgs-short", "nsgs_", "numba", "numba", (FRICTION,), False,
            "friction: 100 projected Gauss–Seidel sweeps, then Newton (more sweeps while they "
            "gain); cheapest on well-conditioned problems"),
    Backend("newton", "newton_", "scipy", "scipy", (FRICTION,), False,
            "friction: Alart–Curnier semismooth Newton from r = 0, sparse LU steps"),
    Backend("newton-damped", "newton_", "scipy", "scipy", (FRICTION,), False,
            "friction: Alart–Curnier Newton with a ten times larger shift of its Jacobian"),
    Backend("newton-repair", "repair_", "clarabel", "clarabel", (FRICTION,), False,
            "friction: Newton with local repairs: where it stalls on a few contacts, their "
            "sub-problem solved by the cone programs' fixed point, then Newton again"),
    Backend("newton-lstsq", "lstsq_", "scipy", "scipy", (FRICTION,), False,
            "friction: least-squares Newton on the natural map, dense, at most 600 unknowns "
            "(rank-deficient W)"),
    Backend("nsgs", "nsgs_", "numba", "numba", (FRICTION,), False,
            "friction: up to 20000 projected Gauss–Seidel sweeps, then Newton"),
)}

AUTO_ORDER = {
    CONE: ("clarabel", "cvxpy"),
    FRICTION: ("kernel", "nsgs-short", "newton", "newton-repair", "clarabel", "newton-damped",
               "newton-lstsq", "nsgs"),
}
"""The order in which ``"auto"`` tries the entries of the cone and friction forms (the
quadratic programs' order depends on the program, :func:`impactqp.qp.certified.auto_order`).
Friction: cheapest where each works first — one compiled call for a few contacts, a short
NSGS on well-conditioned problems, Newton from r = 0 most of the rest, Newton with local
repairs where it stalls on a few contacts (docs/theory.md §22), the SOCP fixed point the
badly conditioned ones, the damped and least-squares Newton some rank-deficient ones, a long
NSGS last; the least-squares Newton and the long NSGS start from the best answer so far, the
SOCP route too unless that answer lies between 10·tol and 1e-4 (from such a stalled answer
it took 2–6 times longer than from r = 0) (docs/theory.md §15, §22)."""

def sub_solvers(entry: Backend) -> list[dict]:
    """The solvers of :data:`SOLVERS` that ``entry`` runs, as ``"family:solver"``, each with
    whether it is installed and what to install (empty for a backend without sub-solvers).

    Returns
    -------
    list of dict
        Keys ``name``, ``installed`` and ``install``.
    """
    if entry.sub_solver == "none":
        return []
    have = set(load(entry).installed_solvers()) if entry.installed else set()
    return [{"name": f"{entry.name}:{s.spelled(entry.name)}",
             "installed": s.spelled(entry.name) in have, "install": s.install}
            for s in SOLVERS.values() if entry.name in s.families]


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


@cache
def _importable(package: str) -> bool:
    return importlib.util.find_spec(package) is not None


def parse_backend(name: object) -> tuple[Backend, str | None]:
    """The registry entry of ``"family"`` or ``"family:solver"`` and the sub-solver name.

    Raises
    ------
    UnknownBackendError
        For a name impactqp does not know (the message lists the known ones).
    """
    if not isinstance(name, str):
        raise UnknownBackendError(f"backend must be a string, got {type(name).__name__}")
    family, _, sub = name.partition(":")
    family = family.strip().lower()
    entry = REGISTRY.get(family)
    if entry is None:
        raise UnknownBackendError(
            f"unknown backend {name!r}; choose one of 'auto', "
            + ", ".join(repr(k) for k in REGISTRY) + " (or 'cvxpy:SOLVER', 'qpsolvers:NAME')")
    sub = sub.strip() or None
    if sub and entry.sub_solver == "none":
        raise UnknownBackendError(f"backend {family!r} takes no sub-solver, got {name!r}")
    return entry, sub


def load(entry: Backend) -> ModuleType:
    """Import a backend's module.

    Raises
    ------
    UnknownBackendError
        When the solver it wraps is not installed (the message says what to install).
    """
    module = _LOADED.get(entry.module)
    if module is not None:
        return module
    try:
        module = importlib.import_module(f".{entry.module}", __name__)
    except ImportError as exc:  # a missing optional solver must not break impactqp
        raise UnknownBackendError(f"backend {entry.name!r} is not installed ({exc}); "
                                  f"install {entry.install}") from exc
    _LOADED[entry.module] = module
    return module


_LOADED: dict[str, ModuleType] = {}
"""The backend modules imported so far, by module name (a lookup per attempt, not a hash
of the whole entry)."""


def check_options(backend: str, options: object) -> dict[str, object]:
    """``options`` for ``backend`` as a dict (empty for None), or InputError: options need a
    named backend that takes them (:attr:`Backend.options`), with string keys."""
    if options is None:
        return {}
    if not isinstance(options, dict) or not all(isinstance(k, str) for k in options):
        raise InputError(f"options must be a dict of solver settings by name, got "
                         f"{type(options).__name__}")
    if not options:
        return {}
    if backend == "auto":
        raise InputError("options are settings of one solver: name the backend they are "
                         "for (e.g. backend='clarabel'), not 'auto'")
    entry, _ = parse_backend(backend)
    if not entry.options:
        takes = ", ".join(repr(b.name) for b in REGISTRY.values() if b.options)
        raise InputError(f"backend {entry.name!r} takes no options (these do: {takes})")
    return dict(options)


def serving(form: str) -> tuple[str, ...]:
    """Names of the backends that serve ``form``, in registry order."""
    return tuple(b.name for b in REGISTRY.values() if form in b.forms)


def cone_backends() -> tuple[str, ...]:
    """Names of the backends that take cone programs (:data:`CONE` among their forms)."""
    return serving(CONE)


_KINDS = {CONE: "cone programs", FRICTION: "frictional contact problems"}


def unsuitable(entry: Backend, qp: object, form: str) -> str | None:
    """Why ``entry`` cannot solve ``qp`` (a program of ``form``), or None when it can."""
    if form in _KINDS and form not in entry.forms:
        return (f"{entry.name!r} does not solve {_KINDS[form]}; the backends that do are "
                + ", ".join(map(repr, serving(form))))
    if form not in entry.forms:
        return f"{entry.name!r} does not solve the {form} form (it serves: {entry.serves})"
    module = load(entry)
    check = getattr(module, "unsuitable_friction" if form == FRICTION else "unsuitable", None)
    return None if check is None else check(qp)


def check_suitable(entry: Backend, qp: object, form: str) -> None:
    """Raise BackendUnsuitableError naming why ``entry`` cannot take ``qp``."""
    reason = unsuitable(entry, qp, form)
    if reason is not None:
        raise BackendUnsuitableError(reason)


def available_backends() -> list[dict]:
    """Every registered backend with what it serves and whether it is installed.

    Returns
    -------
    list of dict
        Keys ``name``, ``installed``, ``forms``, ``exact``, ``serves``, ``install`` and
        ``options`` (what ``options=`` of :func:`impactqp.solve` sets, "" for none).
    """
    return [{"name": b.name, "installed": b.installed, "forms": b.forms, "exact": b.exact,
             "serves": b.serves, "install": b.install, "options": b.options}
            for b in REGISTRY.values()]
