"""What the file readers require of a frictional contact problem's Delassus matrix W beyond
its shape (docs/theory.md §1, §15): W = HᵀM⁻¹H is positive semidefinite, so no diagonal
entry of a W read from a file may be negative."""

from __future__ import annotations

import numpy as np


def negative_diagonal(W, d: int) -> str | None:
    """Where W's diagonal is negative, in words (None where it is not): a Delassus matrix
    HᵀM⁻¹H is positive semidefinite, so no diagonal entry of it is below zero (the file
    readers refuse such a W; a
    :class:`~impactqp.model.friction.FrictionContactProblem` built in Python uses W as
    given)."""
    diagonal = np.asarray(W.diagonal(), dtype=float).ravel()
    bad = np.flatnonzero(diagonal < 0)
    if bad.size == 0:
        return None
    i = int(bad[0])
    return (f"diagonal entry {i} (contact {i // d}, {'normal' if i % d == 0 else 'tangent'}) "
            f"is {diagonal[i]:.6g} < 0, and {bad.size} in all: a Delassus matrix HᵀM⁻¹H is "
            "positive semidefinite")
