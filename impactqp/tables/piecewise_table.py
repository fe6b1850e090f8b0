"""What every piecewise-linear impact law table shares: γ⁺ = Q_i γ⁻ on cone i (docs/theory.md §6,
§7).

A table class provides ``cones`` (each with ``Q``) and ``find_cones``; this mixin adds the
stacked matrices, evaluation of the map and the exact certificate of docs/theory.md §7.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..base.checks import Certificate
from .certificate import certify_sector_table

FloatArray = NDArray[np.float64]


class PiecewiseLinearTable:
    """Mixin for tables of cones with one matrix Q per cone."""

    cones: list

    def find_cones(self, gammas: ArrayLike) -> NDArray[np.intp]:
        """Index of a cone containing each row of ``gammas`` (each table knows how)."""
        raise TypeError(f"{type(self).__name__} must define find_cones")

    @cached_property
    def certificate(self) -> Certificate:
        """The exact docs/theory.md §7 certificate of this table (computed once, on first use)."""
        return certify_sector_table(self)

    @cached_property
    def stacked_Q(self) -> FloatArray:
        """All Q matrices, shape (number of cones, m, m)."""
        return np.stack([c.Q for c in self.cones])

    def apply(self, gamma: ArrayLike) -> FloatArray:
        """γ⁺ = Q_i γ on the cone containing γ; accepts a batch (k × m).

        On a shared boundary every containing cone gives the same value (continuity).
        """
        g = np.asarray(gamma, dtype=float)
        gb = np.atleast_2d(g)
        out = np.einsum("kij,kj->ki", self.stacked_Q[self.find_cones(gb)], gb)
        return out[0] if g.ndim == 1 else out
