"""Exact verification of a piecewise-linear impact law on a chain (docs/theory.md §7).

The docs/theory.md §7 certificate decides every condition on every cone; this module turns it into a
:class:`~impactqp.verification.LawReport` and, for each failed condition, looks for a concrete
counterexample on the worst cone (its rays, its centroid and seeded interior directions),
measured by the same residuals as the sampling verifier so that it can be rechecked.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..model.problem import ImpactProblem
from ..tables.certificate import certify_sector_table, table_mass_matrix
from .report import ADMISSIBILITY, Counterexample, LawReport

INTERIOR_DIRECTIONS = 64
"""Seeded convex combinations of a cone's rays tried when hunting a counterexample."""


def _candidates(cone: Any, rng: np.random.Generator) -> np.ndarray:
    """γ⁻ directions of one cone: its rays, the centroid and random interior points."""
    rays = np.asarray(cone.rays, dtype=float)
    weights = rng.random((INTERIOR_DIRECTIONS, len(rays)))
    return np.vstack([rays, rays.mean(axis=0), weights @ rays])


def _velocities(table: Any, cone: Any, gamma: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A u⁻ with Wᵀu⁻ = γ⁻ (least squares) and u⁺ = u⁻ + M⁻¹WG⁻¹(Q − I)γ⁻ (docs/theory.md §1)."""
    W = np.asarray(table.W, dtype=float)
    u_minus = np.linalg.lstsq(W.T, gamma, rcond=None)[0]
    impulses = np.linalg.solve(table.G, cone.Q @ gamma - gamma)
    return u_minus, u_minus + np.linalg.solve(table_mass_matrix(table), W @ impulses)


def _counterexample(table: Any, base: ImpactProblem, cone: Any, condition: str,
                    rng: np.random.Generator) -> Counterexample | None:
    """The worst candidate of ``cone`` for ``condition``, or None if none violates it."""
    best: Counterexample | None = None
    for gamma in _candidates(cone, rng):
        u_minus, u_plus = _velocities(table, cone, gamma)
        p = base.with_u_minus(u_minus)
        if condition == "non_expansive":  # the pair (u⁻, 0) ↦ (u⁺, 0): the piece is linear
            amount = p.norm(u_plus) / p.norm(u_minus) - 1.0
            candidate = Counterexample(np.stack([u_minus, 0 * u_minus]),
                                       np.stack([u_plus, 0 * u_plus]), condition, amount)
        else:
            m = p.admissible_set().contains(u_plus)
            candidate = Counterexample(u_minus, u_plus, condition, m.residuals[condition])
        if candidate.amount > 0 and (best is None or candidate.amount > best.amount):
            best = candidate
    return best


def certify_table_report(table: Any, *, tol: float, seed: int = 0) -> LawReport:
    """Exact :class:`LawReport` of a piecewise-linear law (docs/theory.md §7).

    ``violations`` counts failing cones per condition (``"non_expansive"``: pieces that
    expand the G⁻¹ or the M norm; ``"continuity"``: 1 when some neighbours disagree).
    """
    cert = certify_sector_table(table)
    flags = {"kinematic": [not c.kinematic for c in cert.cones],
             "kinetic": [not c.kinetic for c in cert.cones],
             "energetic": [not c.energetic for c in cert.cones],
             "non_expansive": [not (c.non_expansive and c.velocity_non_expansive)
                               for c in cert.cones]}
    violations = {k: int(sum(v)) for k, v in flags.items()}
    violations["continuity"] = int(not cert.continuity.passed)
    rng = np.random.default_rng(seed)
    W = np.asarray(table.W, dtype=float)
    base = ImpactProblem(table_mass_matrix(table), W, np.zeros(W.shape[0]))
    found: dict[str, Counterexample] = {}
    for name in (*ADMISSIBILITY, "non_expansive"):
        for i in np.flatnonzero(flags[name]):
            ce = _counterexample(table, base, table.cones[int(i)], name, rng)
            if ce is not None and ce.amount > tol and \
                    (name not in found or ce.amount > found[name].amount):
                found[name] = ce
    return LawReport(ok=not any(violations.values()), violations=violations,
                     counterexamples=found, samples=0, pairs=0, method="exact",
                     certificate=cert)
