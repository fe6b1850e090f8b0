"""The verdict of a membership test u ∈ S (docs/theory.md §2, §16)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

OPTIMIZER_TOL = 1e-6
"""Default tolerance of a verdict reached through an optimizer (an interior-point answer)."""

METHODS = ("exact", "optimizer")
"""The methods of :meth:`~impactqp.AdmissibleSet.contains`."""


def energy_excess(ratio: float) -> float:
    """The energetic residual max(0, ρ² − 1) of ρ = ‖u‖/‖u⁻‖ (docs/theory.md §2): +inf where
    ρ² is beyond the floats (a point that far outside the energy ball is simply not in S)."""
    if not ratio < 1e150:
        return float("inf")
    return max(0.0, ratio * ratio - 1.0)


@dataclass(frozen=True)
class Membership:
    """Verdict on u ∈ S with the residual of each condition (dimensionless, docs/theory.md §2).

    Attributes
    ----------
    member : bool
        The verdict; the object itself is truthy exactly when it is True.
    kinetic : float
        min over Λ ≥ 0 of ‖u − u⁻ − M⁻¹WΛ‖ / ‖u⁻‖ (with friction, over Λ in the friction
        cones; exactly that minimum, or the residual of the projected unique Λ, which is
        zero exactly when the minimum is, docs/theory.md §16).
    kinematic : float
        Largest penetration velocity −γᵢ / (sᵢ‖u⁻‖), sᵢ = sqrt(Gᵢᵢ), or 0 (the normal
        columns only, with friction).
    energetic : float
        (‖u‖² − ‖u⁻‖²)₊ / ‖u⁻‖².
    impulses : ndarray
        A Λ ≥ 0 (in the friction cones, with friction) that best explains u − u⁻ (inf
        where Λ is beyond the float range: the verdict, computed in order-one units, does
        not depend on it).
    method : str
        ``"exact"`` or ``"optimizer"``.
    distance : float or None
        With ``method="optimizer"``: ‖u − proj_S(u)‖ / ‖u⁻‖.
    tol : float
    """

    member: bool
    kinetic: float
    kinematic: float
    energetic: float
    impulses: np.ndarray
    method: str
    tol: float
    distance: float | None = None

    def __bool__(self) -> bool:
        return self.member

    @property
    def residuals(self) -> dict[str, float]:
        return {"kinetic": self.kinetic, "kinematic": self.kinematic, "energetic": self.energetic}

    def failed(self) -> list[str]:
        """Names of the conditions that are violated beyond the tolerance."""
        return [k for k, v in self.residuals.items() if v > self.tol]
