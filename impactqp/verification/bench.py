"""Every backend on the user's own problem: each one's time, its distance to the best certified
answer, the certificate's verdict, and why a backend was refused (docs/theory.md §8, §9, §15).

:func:`compare_backends` solves one impact with one law through every backend of the
registry that serves the law (the families with sub-solvers, ``"cvxpy"`` and ``"qpsolvers"``,
once per solver impactqp names, installed or not), so a backend that is not installed appears
with the extra that installs it; or a frictional contact problem (an FCLib or Siconos file's)
through every friction method. Nothing is trusted: a backend's answer counts only when
impactqp's recomputed certificate passes, and the reference is the certified answer with the
smallest certificate residual relative to its tolerance among the exact backends' answers
(active-set solutions), or among all of them when no exact backend answered (always, for a
frictional contact problem).
"""

from __future__ import annotations

import math
import statistics
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace

import numpy as np

from ..base.checks import DEFAULT_TOL, FRICTION_TOL, Certificate
from ..base.log import verbosity
from ..errors import (
    BackendUnsuitableError,
    InputError,
    NoSolutionError,
    SolverError,
    UnknownBackendError,
)
from ..kernels.first_calls import compiling
from ..laws.base import ImpactLaw
from ..laws.friction import FRICTION_BACKENDS, solve_friction
from ..laws.pipeline import solve
from ..laws.planner import check_law, check_problem
from ..laws.result import FrictionResult, ImpactResult
from ..model.friction import FrictionContactProblem
from ..model.problem import ImpactProblem
from ..qp import backends as registry

CERTIFIED, FAILED, REFUSED = "certified", "failed", "refused"
"""The verdicts of a backend on the compared impact."""

WARM_UP = 2
"""Untimed calls per backend before the timed ones: the first pays compilation and the
solvers' caches, the second what a problem keeps from its first solve (a packed frictional
problem is solved from its pack from the third call on)."""


@dataclass(frozen=True)
class BackendRun:
    """One backend on the compared impact.

    Attributes
    ----------
    backend : str
        The name asked for (``"auto"``, ``"exact"``, ``"cvxpy:SCS"``, ...).
    verdict : {"certified", "failed", "refused"}
        Certified: its answer passed impactqp's certificate; failed: it answered, but no
        answer passed (or the solver gave up); refused: not installed, unknown, or it cannot
        take this law or problem.
    reason : str
        Why it failed or was refused ("" when certified), as the error said it.
    used : str
        What produced the numbers (``result.backend``: ``"auto"`` names the path it took).
    time : float
        Median wall time in seconds of the timed calls (NaN unless certified).
    times : tuple of float
        Every timed call's wall time in seconds.
    error : float
        Distance to the best certified answer (NaN unless certified): ‖u⁺ − u⁺_best‖ / ‖u⁻‖
        in the kinetic norm for an impact, ‖u − u_best‖ / ‖q‖ for a frictional contact
        problem.
    margin : float
        The certificate's largest residual divided by its tolerance (≤ 1 when certified;
        NaN when there is no certificate).
    result : ImpactResult, FrictionResult or None
        The certified result of the first call.
    """

    backend: str
    verdict: str
    reason: str = ""
    used: str = ""
    time: float = math.nan
    times: tuple[float, ...] = ()
    error: float = math.nan
    margin: float = math.nan
    result: ImpactResult | FrictionResult | None = None

    @property
    def certified(self) -> bool:
        return self.verdict == CERTIFIED


@dataclass(frozen=True)
class BackendComparison:
    """Every compared backend on one impact, in the order they ran.

    Attributes
    ----------
    problem : ImpactProblem or FrictionContactProblem
    law : ImpactLaw or None
        The impact's law; None for a frictional contact problem (its μ is its law).
    runs : tuple of BackendRun
    best : str or None
        The backend whose certified answer is the reference of ``error``: an exact backend's
        (registry ``exact``) with the smallest certificate margin, else (and for a
        frictional contact problem) any backend's with the smallest margin; None when no
        backend was certified.
    tol : float
        The certificate tolerance of every solve.
    repeats : int
        Timed calls per certified backend (after two untimed calls that pay compilation and
        caches).
    """

    problem: ImpactProblem | FrictionContactProblem
    law: ImpactLaw | None
    runs: tuple[BackendRun, ...]
    best: str | None
    tol: float
    repeats: int

    def __getitem__(self, backend: str) -> BackendRun:
        for run in self.runs:
            if run.backend == backend:
                return run
        raise KeyError(f"no backend {backend!r} compared; have {[r.backend for r in self.runs]}")

    @property
    def certified(self) -> tuple[BackendRun, ...]:
        """The runs whose answers passed the certificate."""
        return tuple(r for r in self.runs if r.certified)

    def to_rows(self) -> list[dict]:
        """One dict per backend: ``backend``, ``used``, ``verdict``, ``time_s`` (median),
        ``error``, ``margin`` and ``reason``; a number that does not apply is None (so the
        rows go to JSON or a data frame as they are)."""
        def number(x: float) -> float | None:
            return None if math.isnan(x) else x
        return [{"backend": r.backend, "used": r.used, "verdict": r.verdict,
                 "time_s": number(r.time), "error": number(r.error),
                 "margin": number(r.margin), "reason": r.reason} for r in self.runs]

    def __str__(self) -> str:
        p = self.problem
        if self.law is None:
            what, error = (f"Coulomb friction (W, q, μ) on {_count(p.n_contacts, 'contact')} "
                           f"in {p.contact_dim}-D", "‖u − u_best‖/‖q‖")
        else:
            what, error = (f"{self.law.title} on {_count(p.n_dof, 'velocity', 'velocities')} "
                           f"and {_count(p.n_contacts, 'contact')}", "‖u⁺ − u⁺_best‖/‖u⁻‖")
        head = (f"{what}: {len(self.certified)} of {len(self.runs)} backends certified "
                f"(tol {self.tol:.0e}); error = {error} against {self.best!r}; time = median "
                f"of {_count(self.repeats, 'call')} after {WARM_UP} untimed")
        rows = [("backend", "time", "error", "certificate", "why")]
        for r in self.runs:
            name = r.backend if r.used in ("", r.backend) else f"{r.backend} ({r.used})"
            rows.append((name, _duration(r.time), "–" if math.isnan(r.error) else
                         f"{r.error:.1e}", r.verdict, r.reason))
        widths = [max(len(row[i]) for row in rows) for i in range(4)]
        lines = [head, ""]
        for row in rows:
            cells = [cell.ljust(w) for cell, w in zip(row, widths)]
            lines.append("  ".join([*cells, row[4]]).rstrip())
        if (self.law is None or self.law.frictional) and self.certified:
            lines += ["", "Coulomb's law can have several solutions (docs/theory.md §16): "
                          "certified answers may differ by more than the tolerance."]
        return "\n".join(lines)


def _count(n: int, one: str, many: str | None = None) -> str:
    return f"{n} {one if n == 1 else many or one + 's'}"


def _duration(seconds: float) -> str:
    if math.isnan(seconds):
        return "–"
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds * 1e9:.3g} ns"


def default_backends(law: ImpactLaw) -> tuple[str, ...]:
    """``"auto"``, the law's closed form if it has no program, and every registered backend
    that serves one of the law's forms, a family with sub-solvers once per solver impactqp
    names (:data:`impactqp.qp.backends.SOLVERS`), installed or not."""
    if not law.forms:
        return ("auto", law.closed_form_backend)
    names = ["auto"]
    for entry in registry.REGISTRY.values():
        if not set(law.forms) & set(entry.forms):
            continue
        if entry.sub_solver == "none":
            names.append(entry.name)
        else:
            names += [f"{entry.name}:{s.spelled(entry.name)}" for s in registry.SOLVERS.values()
                      if entry.name in s.families]
    return tuple(names)


def _margin(cert: Certificate) -> float:
    """The largest residual over its tolerance."""
    ratios = [v / cert.tol_of(k) for k, v in cert.values.items()]
    return max(ratios, default=0.0)


def _run(call: Callable[[str], ImpactResult | FrictionResult], backend: str,
         repeats: int) -> BackendRun:
    """One backend: :data:`WARM_UP` untimed calls, then ``repeats`` timed ones. Every kernel
    a call reaches compiles at once (:func:`~impactqp.kernels.first_calls.compiling`): run as
    Python, as a fresh process's first small calls are, it would be timed so."""
    try:
        with compiling():
            result = call(backend)
            for _ in range(WARM_UP - 1):
                call(backend)
            times = []
            for _ in range(repeats):
                start = time.perf_counter()
                call(backend)
                times.append(time.perf_counter() - start)
    except (UnknownBackendError, BackendUnsuitableError) as exc:
        return BackendRun(backend, REFUSED, _one_line(exc))
    except InputError:  # the caller's input, not the backend's fault
        raise
    except (SolverError, NoSolutionError) as exc:  # CertificateError is a SolverError
        return BackendRun(backend, FAILED, _one_line(exc))
    return BackendRun(backend, CERTIFIED, used=result.backend, time=statistics.median(times),
                      times=tuple(times), margin=_margin(result.certificate), result=result)


def _rank(run: BackendRun) -> tuple[bool, float]:
    """Answers of exact backends first (active-set solutions, the registry's ``exact``), then
    the smallest certificate margin."""
    entry = registry.REGISTRY.get(run.used.partition(":")[0])
    return (entry is None or not entry.exact), run.margin


def _margin_of(run: BackendRun) -> float:
    """The smallest certificate margin first."""
    return run.margin


def _one_line(exc: Exception) -> str:
    return " ".join(str(exc).split())


def compare_backends(problem: ImpactProblem | FrictionContactProblem,
                     law: ImpactLaw | None = None, backends: Iterable[str] | None = None, *,
                     repeats: int = 3, tol: float | None = None, verbose: bool | int = False
                     ) -> BackendComparison:
    """Solve ``problem`` through each backend and compare them: an impact with ``law``
    (:func:`impactqp.solve`), or a frictional contact problem, whose μ is its law
    (:func:`impactqp.solve_friction`, e.g. ``iq.load_fclib(path)``).

    Parameters
    ----------
    problem : ImpactProblem or FrictionContactProblem
        Any impact (e.g. ``iq.load_problem(path).problem``), or a frictional contact problem.
    law : ImpactLaw, optional
        ``iq.Moreau(0.5)``, ``iq.Newton(e)``, ``iq.Coulomb(mu)``, ...: required for an
        impact, left out for a frictional contact problem.
    backends : iterable of str, optional
        The backends to compare, as :func:`impactqp.solve` takes them (``"auto"``,
        ``"clarabel"``, ``"cvxpy:SCS"``, ``"qpsolvers:highs"``) or, for a frictional
        contact problem, as :func:`impactqp.solve_friction` does; default ``"auto"`` and
        every registered backend that serves the law, the families ``"cvxpy"`` and
        ``"qpsolvers"`` once per solver impactqp names, installed or not
        (:func:`!impactqp.verification.bench.default_backends`), or every friction method.
    repeats : int
        Timed calls per certified backend (≥ 1), after two untimed calls that pay numba's
        compilation (every kernel they reach is compiled, never run as Python), cvxpy's
        problem cache and what a problem keeps from its first solve; the time reported is
        their median.
    tol : float, optional
        Certificate tolerance of every solve; default that of :func:`impactqp.solve`
        (1e-9), or of :func:`impactqp.solve_friction` (1e-8) for a frictional contact
        problem.
    verbose : bool or {0, 1, 2}
        As for :func:`impactqp.solve`: 1 logs refusals and fallbacks; 2 also every attempt,
        and lets the third-party solvers print (they are silenced otherwise).

    Returns
    -------
    BackendComparison
        One :class:`BackendRun` per backend; ``str()`` prints the table, ``to_rows()`` gives
        it as dicts.

    Raises
    ------
    InputError
        Not a problem or a law, a law for a frictional contact problem or none for an
        impact, coefficients that do not fit, a bad ``tol``, ``repeats`` or ``backends`` (a
        backend that is unknown or not installed is a refused row, not an error).
    """
    if isinstance(repeats, bool) or not isinstance(repeats, int) or repeats < 1:
        raise InputError(f"repeats must be an integer ≥ 1, got {repeats!r}")
    if isinstance(problem, FrictionContactProblem):
        if law is not None:
            raise InputError("a FrictionContactProblem carries its law (Coulomb's, with its "
                             f"μ): leave law out (got {law!r}), e.g. iq.compare_backends("
                             "problem) or iq.compare_backends(problem, backends=['auto', "
                             "'nsgs'])")
        tol = FRICTION_TOL if tol is None else tol
        defaults = FRICTION_BACKENDS

        def call(name: str) -> FrictionResult:
            with verbosity(verbose):
                return solve_friction(problem, backend=name, tol=tol)

        def distance(r: FrictionResult, best: FrictionResult) -> float:
            return float(np.linalg.norm(r.u - best.u) / np.linalg.norm(problem.q))
        rank = _margin_of  # no friction method gives an active-set answer
    else:
        check_problem(problem)
        if law is None:
            raise InputError("an impact needs its law: iq.compare_backends(problem, "
                             "iq.Moreau(0.5)) (or iq.Newton(e), iq.Coulomb(mu), ...)")
        check_law(law)
        tol = DEFAULT_TOL if tol is None else tol
        defaults = default_backends(law)

        def call(name: str) -> ImpactResult:
            return solve(problem, law, name, tol=tol, verbose=verbose)

        def distance(r: ImpactResult, best: ImpactResult) -> float:
            return problem.norm(r.u_plus - best.u_plus) / problem.velocity_scale
        rank = _rank
    names = defaults if backends is None else _names(backends)
    runs = [_run(call, name, repeats) for name in names]
    certified = [r for r in runs if r.certified]
    if not certified:
        return BackendComparison(problem, law, tuple(runs), None, tol, repeats)
    best = min(certified, key=rank)
    runs = [replace(r, error=distance(r.result, best.result)) if r.certified else r
            for r in runs]
    return BackendComparison(problem, law, tuple(runs), best.backend, tol, repeats)


def _names(backends: object) -> tuple[str, ...]:
    if isinstance(backends, str):
        raise InputError(f"backends must be a list of backend names, got the string "
                         f"{backends!r} (write [{backends!r}])")
    try:
        names = tuple(backends)  # type: ignore[arg-type]
    except TypeError:
        raise InputError(f"backends must be a list of backend names, got "
                         f"{type(backends).__name__}") from None
    if not names or not all(isinstance(n, str) for n in names):
        raise InputError(f"backends must be a non-empty list of backend names, got {names!r}")
    return names
