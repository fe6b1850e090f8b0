"""Geometric classification of a post-impact velocity (docs/theory.md §4)."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..base.arrays import as_vector
from ..base.checks import UNIT_RANGE
from ..errors import InputError, OutOfRangeError
from .admissible import best_impulses
from .problem import ImpactProblem


@dataclass(frozen=True)
class Classification:
    """Invariants of an impact u⁻ ↦ u⁺ (docs/theory.md §4).

    Attributes
    ----------
    intensity : float
        ‖u⁺ − u⁻‖ in the kinetic metric.
    topology : ndarray
        Unit impulse direction Λ/‖Λ‖ (the half-line of u⁻ + N through u⁺; with redundant
        contacts one of several representations).
    direction : ndarray
        (u⁺ − u⁻)/‖u⁺ − u⁻‖, the same half-line in velocity space (unique).
    alpha_deg : float
        Angle in the metric M between the half-line of u⁺ and Moreau's half-line through z;
        NaN when there is no impact (z⊥ = 0) or u⁺ = u⁻.
    dissipation : float
        The ε whose energy sphere passes through u⁺: ‖u⁺‖² = ‖z‖² + ε²‖z⊥‖²; negative
        (−sqrt(−ratio)) when u⁺ has less energy than z, NaN when z⊥ = 0.
    moreau_direction : ndarray
        (z − u⁻)/‖z − u⁻‖.
    impulses : ndarray
        Λ ≥ 0 that best explains u⁺ − u⁻ (one of several with redundant contacts).
    kinetic_residual : float
        How far u⁺ is from u⁻ + N (relative); the classification assumes it is ~0.
    """

    intensity: float
    topology: np.ndarray
    direction: np.ndarray
    alpha_deg: float
    dissipation: float
    moreau_direction: np.ndarray
    impulses: np.ndarray
    kinetic_residual: float

    def summary(self) -> str:
        """One line with α to 0.01° and the others to four digits: what a classification
        says, without the last bits of round-off (α = 30° computes as 29.999999999999996)."""
        alpha = "undefined" if np.isnan(self.alpha_deg) else f"{self.alpha_deg:.4g}°"
        return (f"α = {alpha}, dissipation ε = {self.dissipation:.4g}, intensity "
                f"{self.intensity:.4g}")

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.summary()})"


def _unit(p: ImpactProblem, v: np.ndarray) -> np.ndarray:
    n = p.norm(v)
    return v / n if n > 0 else np.full_like(v, np.nan)


def classify(problem: ImpactProblem, u_plus: Any) -> Classification:
    """Classify u⁺ by intensity, topology, angle α to Moreau's half-line and dissipation
    (docs/theory.md §4).

    Parameters
    ----------
    problem : ImpactProblem
    u_plus : (n,) array_like
        A post-impact velocity, normally in u⁻ + N.

    Returns
    -------
    Classification

    Raises
    ------
    InputError
        ``problem`` is not an ImpactProblem, has frictional contacts (the invariants are
        those of the frictionless geometry: classify against ``problem.normal_problem()``),
        or ``u_plus`` is not a finite (n,) vector.
    OutOfRangeError
        The intensity or the impulses do not fit in floats (the other invariants would).
    """
    if not isinstance(problem, ImpactProblem):
        raise InputError(f"problem must be an ImpactProblem, got {type(problem).__name__}")
    if problem.contact_dim > 1:
        raise InputError("the classification (docs/theory.md §4) is that of frictionless "
                         "impacts, whose u⁺ − u⁻ lies in the normal cone; for frictional "
                         "contacts classify against problem.normal_problem()")
    u = as_vector("u_plus", u_plus, problem.n_dof)
    scale = max(float(np.abs(problem.u_minus).max(initial=0.0)),
                float(np.abs(u).max(initial=0.0)))
    if scale > 0 and not UNIT_RANGE[0] <= scale <= UNIT_RANGE[1]:
        # every invariant but the intensity and Λ is scale-free: classify in order-one units
        unit = classify(problem.with_u_minus(problem.u_minus / scale), u / scale)
        with np.errstate(over="ignore"):
            intensity, impulses = unit.intensity * scale, unit.impulses * scale
        if not (np.isfinite(intensity) and np.isfinite(impulses).all()):
            raise OutOfRangeError(f"the impact's intensity ({unit.intensity:.3g} × "
                                  f"{scale:.3g}) or its impulses overflow floats")
        return replace(unit, intensity=intensity, impulses=impulses)
    z, zp = problem.moreau_split
    du = u - problem.u_minus
    lam, res = best_impulses(problem, du)
    intensity = problem.norm(du)
    peak = float(np.abs(lam).max(initial=0.0))  # Λ/max|Λᵢ| first: ‖Λ‖² may underflow
    topology = (lam / peak) / np.linalg.norm(lam / peak) if peak > 0 else \
        np.full_like(lam, np.nan)
    direction = _unit(problem, du)
    moreau_dir = _unit(problem, -zp)
    zp2 = problem.norm(zp) ** 2
    if zp2 > 0 and intensity > 0:
        # atan2 of the parallel and orthogonal parts: accurate near 0° (arccos is not)
        cos = problem.inner(direction, moreau_dir)
        sin = problem.norm(direction - cos * moreau_dir)
        alpha = float(np.degrees(np.arctan2(sin, cos)))
        # ‖u⁺‖² − ‖z‖² as ⟨u⁺ − z, u⁺ + z⟩: no cancellation for u⁺ near z (small ε)
        ratio = problem.inner(u - z, u + z) / zp2
        dissipation = float(np.sign(ratio) * np.sqrt(abs(ratio)))
    else:
        alpha, dissipation = float("nan"), float("nan")
    return Classification(intensity=intensity, topology=topology, direction=direction,
                          alpha_deg=alpha, dissipation=dissipation, moreau_direction=moreau_dir,
                          impulses=lam, kinetic_residual=res / problem.velocity_scale)
