"""Coulomb's law of frictional impacts (docs/theory.md §16).

placeholder: the class, its coefficients and their validation only, so that the frictional
Moreau–Jean step can be written against it; the law's solve replaces this file at merge.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..base.arrays import as_array
from ..errors import InputError, RestitutionError
from .base import ImpactLaw


class Coulomb(ImpactLaw):
    """Coulomb friction in De Saxcé's form with Newton's restitution in the normal.

    Parameters
    ----------
    mu : float or (m,) array_like
        Friction coefficients, one for all contacts or one per contact, each ≥ 0.
    restitution : float or (m,) array_like
        Newton's coefficients eᵢ ∈ [0, 1] of the normal velocities.
    """

    name = "coulomb"
    title = "Coulomb's law"

    def __init__(self, mu: Any, restitution: Any = 0.0) -> None:
        self.mu = as_array("mu", mu)
        self.restitution = as_array("restitution", restitution)
        for name, value in (("mu", self.mu), ("restitution", self.restitution)):
            if value.ndim > 1:
                raise InputError(f"{name} must be a number or one per contact, got shape "
                                 f"{value.shape}")
        if (self.mu < 0).any():
            raise InputError(f"mu must be ≥ 0, got {mu!r}")
        if not np.all((self.restitution >= 0) & (self.restitution <= 1)):
            raise RestitutionError(f"restitution must lie in [0, 1], got {restitution!r}")
