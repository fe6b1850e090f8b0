"""The trace of the reaction cone N = {M⁻¹WΛ : Λ ≥ 0} in a plane of velocities (docs/theory.md
§2), as the figures of S need it: a convex cone of the plane, which is a point, a ray, a
wedge, a half-plane or the whole plane.

Directions of the plane are tested by exact membership (the kinetic residual of
:func:`impactqp.model.admissible.best_impulses`, a non-negative least-squares problem), on a
fine polar sweep whose boundary rays are then refined by bisection to the round-off of the
test. Contact directions M⁻¹wᵢ that lie in the plane are generators of the trace and are
taken exactly: when every one does (two independent contacts and their own plane), the
trace is the cone they span, with no sweep at all.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model.admissible import best_impulses

MEMBER_TOL = 1e-12
"""Kinetic residual (relative to the direction's length) up to which a direction of the
plane lies in N."""
SWEEP = 720
"""Directions tested by the polar sweep."""
BISECTIONS = 60
"""Halvings of the angle between an inside and an outside direction of the sweep."""


@dataclass(frozen=True)
class PlaneCone:
    """A convex cone of the plane, in the plane's coordinates.

    Attributes
    ----------
    kind : str
        ``"point"``, ``"ray"``, ``"wedge"`` (angle below π), ``"half-plane"`` or
        ``"plane"``.
    first, last : (2,) ndarray or None
        Unit boundary rays: the cone turns counter-clockwise from ``first`` to ``last``
        (a ray has ``first`` only; a half-plane lies left of ``first``).
    """

    kind: str
    first: np.ndarray | None = None
    last: np.ndarray | None = None

    def halfplanes(self) -> list[tuple[np.ndarray, float]]:
        """A region of the plane as half-planes ``normal · v ≥ 0`` (none for the plane).

        Raises
        ------
        ValueError
            For a ray or a point, which are not regions.
        """
        if self.kind == "plane":
            return []
        if self.kind not in ("wedge", "half-plane"):
            raise ValueError(f"a {self.kind} is not a region of the plane")
        a = self.first
        left = [(np.array([-a[1], a[0]]), 0.0)]
        if self.kind == "half-plane":
            return left
        b = self.last
        return left + [(np.array([b[1], -b[0]]), 0.0)]


def kinetic_frame(M: np.ndarray, directions: list[np.ndarray]) -> np.ndarray | None:
    """M-orthonormal columns spanning the first two independent ``directions`` (Gram–Schmidt
    in the metric M), or None when they span less than a plane."""
    basis: list[np.ndarray] = []
    for d in directions:
        v = np.asarray(d, dtype=float).copy()
        size = np.sqrt(max(v @ M @ v, 0.0))
        if size == 0.0:
            continue
        for _ in range(2):  # twice, for round-off
            for e in basis:
                v = v - (e @ M @ v) * e
        rest = np.sqrt(max(v @ M @ v, 0.0))
        if rest > 1e-9 * size:
            basis.append(v / rest)
        if len(basis) == 2:
            return np.column_stack(basis)
    return None


def _unit(theta: float) -> np.ndarray:
    return np.array([np.cos(theta), np.sin(theta)])


def cone_of_directions(angles: np.ndarray) -> PlaneCone:
    """The convex cone spanned by unit directions given by their angles: the complement of
    the largest angular gap between them (a wedge when the gap exceeds π)."""
    if angles.size == 0:
        return PlaneCone("point")
    a = np.sort(np.mod(angles, 2 * np.pi))
    gaps = np.diff(np.append(a, a[0] + 2 * np.pi))
    k = int(np.argmax(gaps))
    gap = gaps[k]
    if gap > 2 * np.pi - 1e-13:  # every direction the same
        return PlaneCone("ray", _unit(a[0]))
    if gap > np.pi + 1e-13:
        return PlaneCone("wedge", _unit(a[(k + 1) % a.size]), _unit(a[k]))
    if gap > np.pi - 1e-13:
        return PlaneCone("half-plane", _unit(a[(k + 1) % a.size]), _unit(a[k]))
    return PlaneCone("plane")


def reaction_trace(problem: Any, basis: np.ndarray) -> PlaneCone:
    """The trace {y : basis @ y ∈ N} of the reaction cone in the plane spanned by the
    M-orthonormal columns of ``basis`` (docs/theory.md §2).

    Parameters
    ----------
    problem : ImpactProblem
        Frictionless.
    basis : (n, 2) ndarray
        M-orthonormal: basisᵀ M basis = I.

    Returns
    -------
    PlaneCone
    """
    st = problem.structure
    M = np.asarray(st.M.todense()) if hasattr(st.M, "todense") else np.asarray(st.M)
    V = np.asarray(st.solve_mass(np.asarray(st.W.todense() if hasattr(st.W, "todense")
                                            else st.W)))  # columns M⁻¹wᵢ
    coords = basis.T @ M @ V  # their plane coordinates
    off = V - basis @ coords
    norms = np.sqrt(np.einsum("ij,ij->j", V, M @ V))
    offn = np.sqrt(np.maximum(np.einsum("ij,ij->j", off, M @ off), 0.0))
    inside = offn <= 1e-13 * norms
    angles = [np.arctan2(c[1], c[0]) for c in coords[:, inside].T]
    if inside.all():
        return cone_of_directions(np.array(angles))

    def member(theta: float) -> bool:
        return best_impulses(problem, basis @ _unit(theta))[1] <= MEMBER_TOL

    thetas = 2 * np.pi * np.arange(SWEEP) / SWEEP
    hits = np.array([member(t) for t in thetas])
    found = list(angles)
    for k in np.flatnonzero(hits):
        found.append(thetas[k])
        for step in (-1, 1):  # refine where the sweep leaves the cone
            j = (k + step) % SWEEP
            if hits[j]:
                continue
            good, bad = thetas[k], thetas[k] + step * 2 * np.pi / SWEEP
            for _ in range(BISECTIONS):
                mid = 0.5 * (good + bad)
                good, bad = (mid, bad) if member(mid) else (good, mid)
            found.append(good)
    return cone_of_directions(np.array(found))
