"""Which Frémond matrices keep u⁺ in S? A sampled map over a 2-parameter family (docs/theory.md §3).

Frémond's law ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` is not guaranteed to land in S (docs/theory.md §3); this
module
scans a grid of matrices E(a, b) and reports, for each, whether every sampled u⁻ gives an
admissible u⁺ (kinematic, kinetic and energetic residuals within the tolerance).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..base.arrays import as_array, as_count, check_tol
from ..errors import InputError
from ..laws.functions import fremond
from ..model.problem import ImpactProblem
from .parallel import check_jobs, run_chunks, split
from .sampled import DEFAULT_TOL, admissibility_residuals, sample_u_minus

FAMILIES = ("symmetric", "triangular")


def fremond_matrix(a: float, b: float, m: int, family: str = "symmetric") -> np.ndarray:
    """E(a, b) of size m: ``"symmetric"`` aI + b(J − I) (for m = 2, [[a, b], [b, a]]);
    ``"triangular"`` aI + b·(ones above the diagonal) (for m = 2, [[a, b], [0, a]])."""
    if family not in FAMILIES:
        raise InputError(f"family must be one of {FAMILIES}, got {family!r}")
    off = np.ones((m, m)) - np.eye(m) if family == "symmetric" else np.triu(np.ones((m, m)), 1)
    return a * np.eye(m) + b * off


def fremond_admissibility_map(problem: ImpactProblem, a_values: Any, b_values: Any,
                              samples: int = 200, seed: int = 0, *,
                              family: str = "symmetric", consistent_only: bool = True,
                              tol: float = DEFAULT_TOL, n_jobs: int = 1, client: Any = None,
                              progress: bool | None = None) -> np.ndarray:
    """Boolean grid: ``out[i, j]`` is True when E(a_values[i], b_values[j]) keeps u⁺ ∈ S
    for every sampled u⁻.

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W.
    a_values, b_values : 1-D array_like
        Grid of the two parameters of :func:`!impactqp.verification.fremond_map.fremond_matrix`.
    samples, seed : int
        The same seeded u⁻ are used for every cell.
    family : {"symmetric", "triangular"}
    consistent_only : bool
        Sample only γ⁻ ≤ 0 (default), where Moreau's E = εI is known to be admissible.
    tol : float
        Tolerance on the dimensionless residuals of the membership test.
    n_jobs : int
        Local worker processes sharing the cells (-1: every core); the grid does not
        depend on it.
    client : dask.distributed.Client, optional
        Run the cells on this Dask cluster instead (the ``dask`` extra).
    progress : bool or None
        Progress bar on stderr (None: only on a terminal).

    Returns
    -------
    (len(a_values), len(b_values)) ndarray of bool
        True where every sampled u⁻ ends in S.

    Raises
    ------
    InputError
        For grids that are not 1-D, a ``problem`` that is not an ImpactProblem, an unknown
        ``family``, or bad ``samples``, ``seed`` or ``tol``.
    """
    a_values = np.atleast_1d(as_array("a_values", a_values))
    b_values = np.atleast_1d(as_array("b_values", b_values))
    if a_values.ndim != 1 or b_values.ndim != 1:
        raise InputError("a_values and b_values must be 1-D")
    if not isinstance(problem, ImpactProblem):
        raise InputError(f"problem must be an ImpactProblem, got {type(problem).__name__}")
    samples = as_count("samples", samples, minimum=2)
    seed = as_count("seed", seed)
    tol = check_tol(tol)
    m = problem.n_contacts
    if family not in FAMILIES:
        raise InputError(f"family must be one of {FAMILIES}, got {family!r}")
    n_jobs = check_jobs(n_jobs, client)
    u_minus = sample_u_minus(problem, samples, np.random.default_rng(seed),
                             consistent_only=consistent_only)
    cells = [(a, b) for a in a_values for b in b_values]

    def work(span: range) -> list[bool]:
        verdicts = []
        for a, b in (cells[k] for k in span):
            E = fremond_matrix(a, b, m, family)
            _, res, _ = admissibility_residuals(lambda q, E=E: fremond(q, E), problem, u_minus)
            verdicts.append(bool(np.all(res <= tol)))  # NaN (the law failed): not in S
        return verdicts

    chunks = split(len(cells), n_jobs, client=client, impacts_per_item=samples)
    found = run_chunks(work, chunks, n_jobs=n_jobs, client=client,
                       desc="Frémond map", progress=progress)
    return np.array([v for part in found for v in part], dtype=bool).reshape(
        a_values.size, b_values.size)
