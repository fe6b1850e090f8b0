"""The projection onto one contact's Coulomb cone, written from the cone's definition for
the tests to judge the kernels by (docs/theory.md §15)."""

from __future__ import annotations

import numpy as np


def project_onto_cone(x: np.ndarray, mu: float) -> np.ndarray:
    """P_K(x) of one contact (normal first): the point of K_μ = {‖x_T‖ ≤ μ x_n} nearest x,
    by its three cases (inside, in the polar cone, onto the boundary)."""
    xn, xt = x[0], x[1:]
    t = float(np.linalg.norm(xt))
    if t <= mu * xn:
        return x.copy()
    if mu * t <= -xn:
        return np.zeros_like(x)
    a = (xn + mu * t) / (1.0 + mu * mu)
    return np.concatenate([[a], mu * a * xt / t])
