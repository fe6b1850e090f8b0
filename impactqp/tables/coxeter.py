"""Angles of a chain's tangent cone and the reflection (Coxeter) group they generate.

An elastic collision at contact i alone is the M-orthogonal reflection across the facet
γ_i = 0 of T_C (docs/theory.md §1).  Neighbouring facets i, i+1 meet at the dihedral angle
``θ_i = arccos(−G_{i,i+1}/√(G_ii G_{i+1,i+1}))`` in the kinetic metric; facets further
apart are orthogonal (G_{i,i+2} = 0).  When every θ_i is π/k_i the reflections generate a
Coxeter group whose diagram is a path with labels k_i, and T_C (a simplicial cone) is its
chamber.  Its Coxeter form ``B_ij = −cos(π/m_ij)`` is then the normalised Delassus matrix
``D^{-1/2} G D^{-1/2}``, which is positive definite (W has independent columns), so the
group is automatically finite: every path labelled by angles of actual masses is one of
A_r, B_r, F_4, H_3, H_4 or a dihedral group I_2(k).

A chain is described by its *extended masses*: the ball masses with ``inf`` for a wall, so
contact i joins bodies i and i+1 and angle i is at body i+1.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..errors import SectorInputError

ANGLE_TOL = 1e-9
"""Absolute tolerance (radians) for an angle to count as π/k."""

_EXCEPTIONAL = {(3, 4, 3): ("F4", 1152), (5, 3): ("H3", 120), (3, 5): ("H3", 120),
                (5, 3, 3): ("H4", 14400), (3, 3, 5): ("H4", 14400)}


def extended_masses(masses: np.ndarray, left_wall: bool = False,
                    right_wall: bool = False) -> np.ndarray:
    """Ball masses with ``inf`` prepended/appended for a left/right wall (a fixed body)."""
    return np.concatenate([[math.inf] * left_wall, np.asarray(masses, dtype=float),
                           [math.inf] * right_wall])


def contact_angles(G: Any) -> np.ndarray:
    """Dihedral angles θ_i (radians) of T_C between contacts i and i+1 (docs/theory.md §1).

    ``cos θ_i = −G_{i,i+1}/√(G_ii G_{i+1,i+1})``: π minus the angle between the inward
    normals M⁻¹w_i, M⁻¹w_{i+1} of the facets.  For a chain of balls
    ``cos θ_i = (1/m_{i+1})/√((1/m_i + 1/m_{i+1})(1/m_{i+1} + 1/m_{i+2}))``.
    """
    d = np.asarray(G.diagonal(), dtype=float)  # dense or scipy.sparse
    cos = -np.asarray(G.diagonal(1), dtype=float) / np.sqrt(d[:-1] * d[1:])
    return np.arccos(np.clip(cos, -1.0, 1.0))


def coxeter_labels(angles: np.ndarray, tol: float = ANGLE_TOL) -> list[int | None]:
    """``k`` with ``|θ − π/k| ≤ tol`` for each angle, or None when θ is not π/k."""
    out: list[int | None] = []
    for theta in np.asarray(angles, dtype=float):
        k = round(math.pi / theta)
        out.append(k if k >= 2 and abs(theta - math.pi / k) <= tol else None)
    return out


def coxeter_type(labels: Sequence[int]) -> tuple[str, int] | None:
    """Name and order of the Coxeter group of a path diagram with edge labels ≥ 3.

    ``labels[i]`` joins nodes i and i+1 (so r = len(labels) + 1 generators).  Returns None
    when the path is not of finite type (e.g. (4, 4), (6, 3)).
    """
    ks = tuple(int(k) for k in labels)
    r = len(ks) + 1
    if r == 1:
        return "A1", 2
    if r == 2:
        return {3: "A2", 4: "B2", 6: "G2"}.get(ks[0], f"I2({ks[0]})"), 2 * ks[0]
    if all(k == 3 for k in ks):
        return f"A{r}", math.factorial(r + 1)
    if all(k == 3 for k in ks[1:-1]) and sorted((ks[0], ks[-1])) == [3, 4]:
        return f"B{r}", 2**r * math.factorial(r)
    return _EXCEPTIONAL.get(ks)


def shared_mass(theta: float, m_left: float, m_right: float) -> float:
    """Mass of the body shared by two neighbouring contacts that makes their angle θ.

    With a = 1/m_left, c = 1/m_right (0 for a wall) and b = 1/m, ``cos θ = b/√((a+b)(b+c))``
    gives ``sin²θ b² − (a+c)cos²θ b − ac cos²θ = 0``; b is its positive root.

    Raises
    ------
    SectorInputError
        If θ ∉ (0, π/2) (90° needs an infinitely heavy shared body) or both neighbours
        are walls.
    """
    if not 0.0 < theta < math.pi / 2:
        raise SectorInputError(
            f"no finite masses give an angle of {math.degrees(theta):.6g}°: every angle of a "
            "chain lies in (0°, 90°); 90° would need 1/m = 0 for the shared ball")
    a, c = 1.0 / m_left, 1.0 / m_right
    if a == c == 0.0:
        raise SectorInputError("a ball between two walls has no angle to adjust")
    c2, s2 = math.cos(theta) ** 2, math.sin(theta) ** 2
    b = ((a + c) * c2 + math.sqrt(((a + c) * c2) ** 2 + 4 * s2 * a * c * c2)) / (2 * s2)
    return 1.0 / b


def continuous_mass_ratios(k: int, m1: float = 1.0, m3: float = 1.0) -> np.ndarray:
    """Masses (m1, m2, m3) of three balls whose contact angle is exactly π/k (docs/theory.md §1).

    For m1 = m3 = 1: ``cos θ = 1/(1 + m2)``, so ``m2 = 1/cos(π/k) − 1``: 1 for k = 3
    (equal masses), √2 − 1 for k = 4, √5 − 2 for k = 5, 2/√3 − 1 for k = 6.  k = 2 (90°)
    is not attainable: it needs 1/m2 = 0.

    Parameters
    ----------
    k : int
        The angle of T_C is π/k; k ≥ 3.
    m1, m3 : float
        Masses of the outer balls (positive).

    Returns
    -------
    (3,) ndarray
        The masses (m1, m2, m3).

    Raises
    ------
    SectorInputError
        If k is not an integer ≥ 3 or a mass is not positive and finite.
    """
    if not isinstance(k, (int, np.integer)) or k < 2:
        raise SectorInputError(f"k must be an integer >= 3, got {k!r}")
    if k == 2:
        raise SectorInputError("k = 2 (90°) is not attainable with finite masses: "
                               "cos θ = 0 needs 1/m2 = 0 (an infinitely heavy middle ball)")
    for name, m in (("m1", m1), ("m3", m3)):
        if not (np.isfinite(m) and m > 0):
            raise SectorInputError(f"{name} must be positive and finite, got {m!r}")
    return np.array([m1, shared_mass(math.pi / k, m1, m3), m3], dtype=float)
