"""The verdict every certificate of impactqp shares: named residuals, each within ``tol``.

A residual that is NaN or infinite fails: a check that cannot be evaluated never passes.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass

DEFAULT_TOL = 1e-9
"""Default tolerance of the dimensionless residuals of a certificate (docs/theory.md §8)."""

UNIT_RANGE = (1e-100, 1e100)
"""Velocity scales (largest |u⁻ᵢ|) worked with as given; beyond them, scale-free answers are
computed in order-one units and scaled back (docs/theory.md §8): norms and products of
1e±160 velocities leave the float range."""


class ResidualChecks(ABC):
    """Verdict shared by every certificate: each of its
    :attr:`~impactqp.results.ResidualChecks.residuals` ≤ ``tol``."""

    tol: float

    @property
    @abstractmethod
    def residuals(self) -> dict[str, float]:
        """The named dimensionless residuals of this certificate."""

    @property
    def ok(self) -> bool:
        """True when every residual is finite and within ``tol``."""
        return all(math.isfinite(v) and v <= self.tol for v in self.residuals.values())

    @property
    def worst(self) -> tuple[str, float]:
        """The largest residual and its name (a non-finite one counts as the largest)."""
        res = self.residuals
        if not res:
            return "none", 0.0
        name = max(res, key=lambda k: res[k] if math.isfinite(res[k]) else math.inf)
        return name, res[name]

    def __bool__(self) -> bool:
        return self.ok

    def summary(self) -> str:
        """One line: the verdict, the tolerance and every residual."""
        parts = ", ".join(f"{k}={v:.1e}" for k, v in self.residuals.items())
        return f"{'ok' if self.ok else 'FAILED'} (tol {self.tol:.0e}): {parts}"


@dataclass(frozen=True)
class NamedChecks(ResidualChecks):
    """A certificate given directly by its residuals (LCPs, programs without physics)."""

    values: dict
    tol: float

    @property
    def residuals(self) -> dict[str, float]:
        return self.values
