"""Benchmark problem families, their sizes per suite, and the exact reference answers.

Every case is seeded and built before any timer starts. A case's ``size`` is the number the
plot puts on its x-axis: balls N for chains, contacts m for dense and packing problems, the
mass ratio r for the mass-ratio chains, and the number of impacts k for batches.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

import impactqp as iq
from impactqp.model.programs import velocity_program
from impactqp.qp.backends.clarabel_ import solve as clarabel_solve
from impactqp.qp.isotonic import chain_moreau
from impactqp.qp.polish import polish

#: how many impacts of a batch case are checked against single exact solves
BATCH_SAMPLE = 50


@dataclass
class Case:
    """One seeded problem of a family, ready to solve.

    Attributes
    ----------
    family, size, instance
        Family name, x-axis value and seed index.
    kind : {"chain", "dense", "sparse", "batch"}
        What the problem looks like to the methods (chains are also sparse when N > 200).
    problem : ImpactProblem
        M, W and u⁻ (for batches: the structure; the rows are in ``U``).
    eps : float
        Moreau restitution ε.
    U : (k, n) ndarray, optional
        Pre-impact velocities of a batch case.
    reference : (n,) or (s, n) ndarray
        The exact u⁺ (for batches: of the rows ``sample``), filled by :func:`attach_reference`.
    ref_label : str
        Which path produced ``reference``.
    """

    family: str
    size: int
    instance: int
    kind: str
    problem: iq.ImpactProblem
    eps: float = 0.0
    U: np.ndarray | None = None
    sample: np.ndarray | None = None
    reference: np.ndarray | None = None
    ref_label: str = ""
    extra: dict = field(default_factory=dict)

    @property
    def n_contacts(self) -> int:
        return self.problem.n_contacts

    @property
    def work(self) -> int:
        """The problem's bulk: k impacts for batches, else max(n, m) (size caps use it)."""
        if self.U is not None:
            return self.U.shape[0]
        return max(self.problem.n_dof, self.problem.n_contacts)

    @property
    def label(self) -> str:
        return f"{self.family} {SIZE_LABEL[self.family]}={self.size:g} #{self.instance}"


def disc_packing(side: int, *, seed: int = 0, pushers: int | None = None,
                 jitter: float = 0.1) -> iq.ImpactProblem:
    """Equal frictionless discs on a hexagonal lattice, every touching pair in contact.

    Parameters
    ----------
    side : int
        The lattice has ``side × side`` discs (n = side², 2 DOF each, m ≈ 3·side² contacts).
    seed : int
        Seeds the masses (uniform in [0.5, 2]) and the velocity jitter.
    pushers : int, optional
        How many discs of the left edge move right at speed 1 (default ``max(1, side // 4)``).
    jitter : float
        Standard deviation of random velocities added to every disc.

    Returns
    -------
    ImpactProblem
        Sparse, diagonal M; W (2n × m) column for the pair (a, b) is −n on a, +n on b with
        n the unit vector from a to b (gap |q_b − q_a| − 2r, r = ½). Redundant contacts
        (m > 2n) make the Delassus matrix singular, as in any dense packing.
    """
    rng = np.random.default_rng(seed)
    i, j = np.meshgrid(np.arange(side), np.arange(side), indexing="xy")
    xy = np.column_stack([(i + 0.5 * (j % 2)).ravel(), (np.sqrt(3) / 2 * j).ravel()])
    pairs = np.array(sorted(cKDTree(xy).query_pairs(1.0 + 1e-9)), dtype=int).reshape(-1, 2)
    a, b = pairs[:, 0], pairs[:, 1]
    normal = xy[b] - xy[a]
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    cols = np.repeat(np.arange(len(pairs)), 4)
    rows = np.column_stack([2 * a, 2 * a + 1, 2 * b, 2 * b + 1]).ravel()
    vals = np.column_stack([-normal, normal]).ravel()
    n = side * side
    W = sp.csc_matrix((vals, (rows, cols)), shape=(2 * n, len(pairs)))
    masses = np.repeat(rng.uniform(0.5, 2.0, n), 2)
    u = jitter * rng.standard_normal(2 * n)
    left_edge = np.flatnonzero(i.ravel() == 0)[: pushers or max(1, side // 4)]
    u[2 * left_edge] += 1.0
    return iq.ImpactProblem(sp.diags(masses, format="csc"), W, u)


def _cradle(size: int, seed: int) -> Case:
    return Case("cradle", size, seed, "chain", iq.newtons_cradle(size))


def _random(size: int, seed: int) -> Case:
    p = iq.random_impact(2 * size, size, seed=seed)
    return Case("random", size, seed, "dense", p, eps=0.5)


def _redundant(size: int, seed: int) -> Case:
    p = iq.random_impact(size, size, seed=seed, redundant=max(1, size // 3))
    return Case("redundant", size, seed, "dense", p, eps=0.5)


def _mass_ratio(size: int, seed: int) -> Case:
    n = 200
    masses = np.where(np.arange(n) % 2 == 0, 1.0, float(size))
    u = np.zeros(n)
    u[0] = 1.0
    return Case("mass-ratio", size, seed, "chain", iq.chain(masses, u), eps=1.0)


def _discs(size: int, seed: int) -> Case:
    side = max(2, int(round(np.sqrt(size / 3.0))))
    p = disc_packing(side, seed=seed)
    return Case("discs", p.n_contacts, seed, "sparse", p)


def _random_chain(size: int, seed: int) -> Case:
    """Equal balls, u⁻ standard normal: every contact may be active, blocks of any length."""
    u = np.random.default_rng(seed).standard_normal(size)
    return Case("chain-random", size, seed, "chain", iq.chain(np.ones(size), u))


def _batch(size: int, seed: int) -> Case:
    rng = np.random.default_rng(seed)
    U = rng.standard_normal((size, 3))
    sample = rng.choice(size, size=min(size, BATCH_SAMPLE), replace=False)
    return Case("batch", size, seed, "batch", iq.newtons_cradle(3), U=U, sample=sample)


BUILDERS: dict[str, Callable[[int, int], Case]] = {
    "cradle": _cradle, "random": _random, "redundant": _redundant,
    "mass-ratio": _mass_ratio, "discs": _discs, "batch": _batch,
    "chain-random": _random_chain,
}
#: families of whole runs (benchmarks/dynamics.py): reported, not plotted
RUN_FAMILIES = {"sim-ball": "steps", "sim-cradle": "N", "sim-column": "N", "event-ball": "T",
                "lzb": "N", "startup": "cases", "friction-impact": "contacts"}
SIZE_LABEL = {"cradle": "N", "chain-random": "N", "random": "m", "redundant": "m",
              "mass-ratio": "r", "discs": "m", "batch": "k", "sweep": "cells", **RUN_FAMILIES}
#: seeded instances per size (only the random families vary with the seed)
INSTANCES = {"random": 3, "redundant": 3}

SUITES: dict[str, dict[str, list[int]]] = {
    "smoke": {"cradle": [3, 100], "random": [5], "discs": [30], "batch": [1000]},
    "quick": {"cradle": [3, 100, 10_000], "random": [2, 4, 10, 50], "redundant": [6],
              "mass-ratio": [1_000_000], "discs": [300], "batch": [10_000]},
    "full": {"cradle": [3, 10, 100, 1000, 10_000, 100_000, 1_000_000],
             "random": [2, 4, 5, 10, 20, 50], "redundant": [6, 12, 30, 50],
             "mass-ratio": [10, 1000, 1_000_000], "discs": [100, 1000, 10_000],
             "batch": [10_000, 100_000, 1_000_000, 10_000_000],
             "chain-random": [1_000_000]},
    "friction": {},  # the friction rows alone (benchmarks/friction.py, friction_impacts.py)
    "fclib-wide": {},  # the friction suite's problems and the widened FCLib/Siconos set
}


def cases(suite: str) -> Iterator[Case]:
    """Yield the seeded cases of a suite (built lazily, one at a time)."""
    for family, sizes in SUITES[suite].items():
        for size in sizes:
            for seed in range(INSTANCES.get(family, 1)):
                yield BUILDERS[family](size, seed)


def count_cases(suite: str) -> int:
    """How many cases :func:`cases` yields."""
    return sum(len(s) * INSTANCES.get(f, 1) for f, s in SUITES[suite].items())


def _tight_clarabel(problem: iq.ImpactProblem, eps: float) -> tuple[np.ndarray, str]:
    qp = velocity_program(problem)
    for tol in (1e-10, 1e-8):  # the tightest tolerance Clarabel reaches
        try:
            sol = clarabel_solve(qp, tol=tol)
            break
        except iq.SolverError:
            continue
    polished = polish(qp, sol)  # exact active-set solve, also with redundant contacts
    z, how = (sol.x, "unpolished") if polished is None else (polished.x, "impactqp polish")
    return (1.0 + eps) * z - eps * problem.u_minus, f"reference: clarabel+polish ({how})"


def attach_reference(case: Case) -> None:
    """Set ``case.reference`` (exact u⁺) and ``case.ref_label`` (its path)."""
    p = case.problem
    if case.kind == "batch":
        rows = case.U[case.sample]
        case.reference = np.array([iq.moreau(p.with_u_minus(u), case.eps, "exact").u_plus
                                   for u in rows])
        case.extra["sorted"] = np.sort(rows, axis=1)
        case.ref_label = "exact (sampled rows); sort for the sector law"
    elif case.family == "cradle":
        # ε = 0: all balls at v/N (docs/theory.md §5)
        case.reference = np.full(p.n_dof, 1.0 / p.n_dof)
        case.ref_label = "closed form v/N"
    elif p.chain is not None:
        c = p.chain
        case.reference = chain_moreau(c.masses, p.u_minus, case.eps, left_wall=c.left_wall,
                                      right_wall=c.right_wall).u_plus
        case.ref_label = "isotonic"
    elif not p.structure.sparse:
        backend = "kernel" if p.n_contacts <= 10 else "exact" if p.n_contacts <= 12 else "nnls"
        try:
            case.reference = iq.moreau(p, case.eps, backend).u_plus
        except iq.ImpactError:  # nnls refuses q ∉ range(G); exact velocity-form polish
            case.reference, backend = _tight_clarabel(p, case.eps)
        case.ref_label = backend
    else:
        case.reference, case.ref_label = _tight_clarabel(p, case.eps)
