"""A verifier for any impact law: is u⁺ in S (docs/theory.md §2), is the law non-expansive
(docs/theory.md §6)?

A law is sampled: pre-impact velocities u⁻ are drawn (seeded) for the M and W of a problem,
kinematically consistent ones (γ⁻ ≤ 0) unless asked otherwise; the law is run on each, and
every answer is checked for the three conditions of S (kinematic γ⁺ ≥ 0, kinetic
u⁺ − u⁻ ∈ N, energetic T⁺ ≤ T⁻) by the exact membership test of
:class:`~impactqp.AdmissibleSet`. Maximal monotonicity is equivalent to non-expansiveness of
u⁻ ↦ u⁺ in the metric M (docs/theory.md §6); its evidence is checked on every pair of
samples. A piecewise-linear law (a :class:`~impactqp.tables.SectorTable`, or any object with
``cones``, ``G`` and ``W``) is certified exactly instead (docs/theory.md §7).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

import numpy as np

from ..base.arrays import as_count, as_dense, as_flag, as_vector, check_tol
from ..base.log import verbosity
from ..errors import InputError, NonFiniteError
from ..laws.base import ImpactLaw
from ..laws.functions import moreau
from ..laws.pipeline import solve
from ..laws.planner import check_friction
from ..laws.result import ImpactResult
from ..model.problem import ImpactProblem
from ..tables.piecewise_table import PiecewiseLinearTable
from .exact import certify_table_report
from .parallel import check_jobs, run_chunks, split
from .report import ADMISSIBILITY, DEFAULT_TOL, Counterexample, LawReport

Law = Callable[[ImpactProblem], Any]

MAX_PAIR_SAMPLES = 1500
"""Non-expansiveness is checked on all pairs of at most this many samples (memory ~ k²)."""


# --------------------------------------------------------------------------- sampling
def sample_u_minus(problem: ImpactProblem, samples: int, rng: np.random.Generator, *,
                   consistent_only: bool = False) -> np.ndarray:
    """Draw u⁻ isotropic in the metric M, or (``consistent_only``) with γ⁻ = Wᵀu⁻ ≤ 0.

    Consistent samples: with independent W (G invertible) γ⁻ = −|Wᵀv'| is drawn from the
    folded normal of covariance G and u⁻ = v + M⁻¹WG⁻¹(γ⁻ − Wᵀv) keeps an isotropic part in
    ker Wᵀ; with redundant contacts u⁻ = −prox_{T_C}(v) (docs/theory.md §1), which lies in −T_C.
    With frictional contacts only the normal velocities are constrained (W's normal
    columns, docs/theory.md §16).
    """
    problem = problem.normal_problem()  # only the normals (docs/theory.md §16)
    st = problem.structure
    W = as_dense(st.W)
    L = np.linalg.cholesky(as_dense(st.M)) if st.sparse else st.cholesky_factor

    def isotropic() -> np.ndarray:  # uᵀMu = ξᵀξ
        return np.linalg.solve(L.T, rng.standard_normal((st.n, samples))).T

    v = isotropic()
    if not consistent_only or st.m == 0:
        return v
    if np.linalg.matrix_rank(W) == st.m:
        gamma = -np.abs(isotropic() @ W)
        lift = as_dense(st.Minv_W) @ np.linalg.inv(as_dense(st.delassus))
        return v + (gamma - v @ W) @ lift.T
    return np.array([-moreau(problem.with_u_minus(x), eps=0.0).u_plus for x in v])


def _solve_with(law: ImpactLaw, problem: ImpactProblem) -> ImpactResult:
    return solve(problem, law)


def run_law(law: Law, problem: ImpactProblem) -> np.ndarray:
    """u⁺ of ``law`` on ``problem``: from an ImpactResult or an (n,) array of real numbers,
    read by the one input converter (complex, strings or a wrong shape are refused by name;
    a non-finite u⁺ raises NonFiniteError)."""
    out = law(problem)
    u = out.u_plus if isinstance(out, ImpactResult) else out
    return as_vector("the law's u⁺", u, problem.n_dof)


def admissibility_residuals(law: Law, problem: ImpactProblem, u_minus: np.ndarray,
                            mu: Any = None) -> tuple[np.ndarray, np.ndarray, list[str | None]]:
    """Run ``law`` from every row of ``u_minus``; return u⁺ (k × n), the residuals (k × 3:
    kinematic, kinetic, energetic) of the exact test u⁺ ∈ S (with the friction cones of
    ``mu`` for frictional contacts, docs/theory.md §16), and per row the error the law
    raised (``"Type: message"``) or None. A row where the law raised, or answered a
    non-finite u⁺, gets u⁺ = NaN and residuals NaN; output that is no real vector of the
    right length (complex, strings, a wrong shape) is a broken law and raises."""
    u_plus = np.full_like(u_minus, np.nan)
    res = np.full((len(u_minus), 3), np.nan)
    errors: list[str | None] = [None] * len(u_minus)
    for i, u in enumerate(u_minus):
        q = problem.with_u_minus(u)
        try:
            out = law(q)
        except Exception as exc:  # the law's own failure at this u⁻: reported, not hidden
            errors[i] = f"{type(exc).__name__}: {exc}"
            continue
        try:
            u_plus[i] = as_vector("the law's u⁺", out.u_plus if isinstance(out, ImpactResult)
                                  else out, problem.n_dof)
        except NonFiniteError as exc:
            errors[i] = f"{type(exc).__name__}: {exc}"
            continue
        m = q.admissible_set(mu).contains(u_plus[i])
        res[i] = m.kinematic, m.kinetic, m.energetic
    return u_plus, res, errors


def _pair_expansion(M: np.ndarray, u_minus: np.ndarray, u_plus: np.ndarray,
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Relative expansion ‖Δu⁺‖/‖Δu⁻‖ − 1 of every pair i < j among the first
    :data:`MAX_PAIR_SAMPLES` finite rows, and the pair indices (p × 2)."""
    keep = np.flatnonzero(np.all(np.isfinite(u_plus), axis=1))[:MAX_PAIR_SAMPLES]
    i, j = np.triu_indices(len(keep), k=1)
    i, j = keep[i], keep[j]

    def dist(u: np.ndarray) -> np.ndarray:
        gram = u @ M @ u.T
        d2 = np.diag(gram)[i] + np.diag(gram)[j] - 2 * gram[i, j]
        return np.sqrt(np.maximum(d2, 0.0))

    before, after = dist(u_minus), dist(u_plus)
    scale = max(float(before.max(initial=0.0)), 1e-300)
    return (after - before) / np.maximum(before, 1e-12 * scale), np.stack([i, j], axis=1)


# --------------------------------------------------------------------------- entry point
def verify_law(law: Any, problem: ImpactProblem | None = None, samples: int = 1000,
               seed: int = 0, consistent_only: bool = True, *,
               tol: float = DEFAULT_TOL, n_jobs: int = 1, client: Any = None,
               progress: bool | None = None, verbose: bool | int = False,
               mu: Any = None) -> LawReport:
    """Check an impact law against S (docs/theory.md §2) and for non-expansiveness
    (docs/theory.md §6).

    By default only kinematically consistent pre-impact velocities are sampled (γ⁻ = Wᵀu⁻ ≤ 0:
    no closed contact is already separating or penetrating from the wrong side), the impacts a
    law meets in a simulation. ``consistent_only=False`` samples u⁻ isotropically in the
    kinetic metric instead, which also tests the law on inconsistent u⁻ (where Moreau's law
    may end penetrating and local Newton may gain energy).

    Parameters
    ----------
    law : ImpactLaw, callable or SectorTable
        A law object (solved by :func:`impactqp.solve`), or ``law(problem)`` returning an
        :class:`~impactqp.ImpactResult` or u⁺ as an (n,) array.
        A piecewise-linear law (``cones`` with ``rays``, ``Q``, ``label``; ``G``; ``W``) is
        certified exactly instead of sampled (docs/theory.md §7).
    problem : ImpactProblem
        Supplies M and W (its u⁻ is not used); not needed for an exact certificate.
    samples : int
        Number of pre-impact velocities (at least 2).
    seed : int
        Seed of the sampling.
    consistent_only : bool
        Sample only kinematically consistent u⁻ (γ⁻ ≤ 0), the default; False samples any u⁻.
    tol : float
        Tolerance on the dimensionless residuals.
    n_jobs : int
        Local worker processes sharing the samples (-1: every core). The samples are drawn
        before they are shared out, so the report does not depend on it.
    client : dask.distributed.Client, optional
        Run on this Dask cluster instead (the ``dask`` extra), at least 10⁴ impacts a task.
    progress : bool or None
        Progress bar on stderr (None: only on a terminal).
    verbose : bool or {0, 1, 2}
        impactqp's log on stderr while it runs (as :func:`impactqp.solve`).
    mu : float or (m,) array_like, optional
        For a problem with frictional contacts (``contact_dim`` 2 or 3): the friction
        coefficients of S (docs/theory.md §16), by default those of a frictional law object
        such as :class:`~impactqp.Coulomb`; required for a callable law. Consistent samples
        then have γ⁻_n ≤ 0 on the normal columns only.

    Returns
    -------
    LawReport
        Violation counts per condition (kinematic, kinetic, energetic, non_expansive,
        law_error) and a recheckable counterexample for each violated one.

    Raises
    ------
    InputError
        If ``law`` is neither callable nor a piecewise-linear table, ``problem`` is not an
        :class:`~impactqp.ImpactProblem`, or ``samples`` is not an integer ≥ 2.
    ShapeError, InputError
        If the law returns u⁺ of the wrong shape, complex or not numbers at all (a law that
        raises, or answers NaN, at some u⁻ is counted as ``law_error`` instead, its
        exception's type and message on the counterexample).
    """
    if verbose:
        with verbosity(verbose):
            return verify_law(law, problem, samples, seed, consistent_only, tol=tol,
                              n_jobs=n_jobs, client=client, progress=progress, mu=mu)
    if isinstance(law, PiecewiseLinearTable) or (hasattr(law, "cones") and hasattr(law, "G")):
        return certify_table_report(law, tol=tol)
    if not callable(law) and not isinstance(law, ImpactLaw):
        raise InputError(f"law must be an impact law, a callable or a piecewise-linear table, got "
                         f"{type(law).__name__}")
    if not isinstance(problem, ImpactProblem):
        raise InputError(f"problem must be an ImpactProblem, got {type(problem).__name__}")
    if isinstance(law, ImpactLaw):
        check_friction(problem, law)
        if mu is None and problem.contact_dim > 1:
            mu = law.admissible_set(problem).mu
        law = partial(_solve_with, law)
    problem.admissible_set(mu)  # μ checked against the problem before any sample
    if not isinstance(samples, (int, np.integer)) or samples < 2:
        raise InputError(f"samples must be an integer ≥ 2, got {samples!r}")
    seed = as_count("seed", seed)
    consistent_only = as_flag("consistent_only", consistent_only)
    tol = check_tol(tol)
    n_jobs = check_jobs(n_jobs, client)
    rng = np.random.default_rng(seed)
    u_minus = sample_u_minus(problem, samples, rng, consistent_only=consistent_only)
    chunks = split(samples, n_jobs, client=client, min_chunk=16)
    parts = run_chunks(lambda span: admissibility_residuals(law, problem, u_minus[span.start:
                                                                                 span.stop],
                                                            mu),
                       chunks, n_jobs=n_jobs, client=client, desc="verify_law",
                       progress=progress)
    u_plus = np.concatenate([part[0] for part in parts])
    res = np.concatenate([part[1] for part in parts])
    errors = [e for part in parts for e in part[2]]
    st = problem.structure
    expansion, pairs = _pair_expansion(as_dense(st.M), u_minus, u_plus)

    failed = np.isnan(res[:, 0])
    violations = {name: int(np.sum(res[:, k] > tol)) for k, name in enumerate(ADMISSIBILITY)}
    violations["non_expansive"] = int(np.sum(expansion > tol))
    violations["law_error"] = int(failed.sum())
    found: dict[str, Counterexample] = {}
    for k, name in enumerate(ADMISSIBILITY):
        if violations[name]:
            i = int(np.nanargmax(res[:, k]))
            found[name] = Counterexample(u_minus[i], u_plus[i], name, float(res[i, k]))
    if violations["non_expansive"]:
        a, b = pairs[int(np.argmax(expansion))]
        found["non_expansive"] = Counterexample(u_minus[[a, b]], u_plus[[a, b]],
                                                "non_expansive", float(expansion.max()))
    if violations["law_error"]:
        i = int(np.flatnonzero(failed)[0])
        found["law_error"] = Counterexample(u_minus[i], u_plus[i], "law_error", float("inf"),
                                            error=errors[i])
    return LawReport(ok=not any(violations.values()), violations=violations,
                     counterexamples=found, samples=int(samples), pairs=len(pairs),
                     method="sampled")
