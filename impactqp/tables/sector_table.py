"""The Winandy–Leine maximal-monotone sector law for a chain of N equal balls.

Pure numpy core (docs/theory.md §1, §5, §6).  For equal masses an elastic
collision of two neighbours swaps their velocities, so the law is
``u⁺ = sort(u⁻)`` (ascending).  In gap-velocity coordinates ``γ = Wᵀu`` the law
is piecewise linear: every ordering π of the velocities is one simplicial cone
``K_π = {γ : H_π γ ≥ 0}`` of γ-space (dimension n−1), on which ``γ⁺ = Q_π γ⁻``.
All matrices are derived from ``W``, a permutation matrix and the cumulative-sum
lift; none is typed by hand.  The exact certificate (docs/theory.md §7) lives in
:mod:`impactqp.tables.certificate` and is attached lazily as
``SectorTable.certificate``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import SectorInputError, SectorTableTooLarge
from .certificate import table_report
from .piecewise_table import PiecewiseLinearTable

MAX_TABLE_BALLS = 8
"""Largest ball count for which :func:`sector_law_table` enumerates the n! cones."""

FloatArray = NDArray[np.float64]


# --------------------------------------------------------------------------- matrices
def chain_matrices(n_balls: int, mass: float = 1.0) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Mass matrix, contact directions and Delassus matrix of a chain (docs/theory.md §1, §5).

    Gaps ``g_i = q_{i+1} − q_i``, so column i of ``W`` is ``∂g_i/∂q = e_{i+1} − e_i``.

    Returns
    -------
    M, W, G : ndarray
        ``M = m I`` (n × n), ``W`` (n × (n−1)) and ``G = WᵀM⁻¹W`` ((n−1) × (n−1)).
    """
    _check_balls(n_balls, mass)
    eye = np.eye(n_balls)
    W = eye[:, 1:] - eye[:, :-1]
    M = mass * eye
    G = W.T @ np.linalg.solve(M, W)
    return M, W, G


def lift_matrix(n_balls: int) -> FloatArray:
    """Cumulative-sum lift ``R`` (n × (n−1)) from gaps to velocities, ``u_1 = 0``.

    ``u_j = Σ_{i<j} γ_i``; it is a right inverse of ``Wᵀ``: ``Wᵀ R = I``.
    """
    return np.tril(np.ones((n_balls, n_balls - 1)), k=-1)


def permutation_matrix(permutation: Sequence[int]) -> FloatArray:
    """Matrix ``P`` with ``(P u)_k = u_{π(k)}`` (0-based indices)."""
    n = len(permutation)
    P = np.zeros((n, n))
    P[np.arange(n), list(permutation)] = 1.0
    return P


def cone_inequalities(permutation: Sequence[int]) -> FloatArray:
    """Matrix ``H`` with ``K_π = {γ : Hγ ≥ 0}`` (docs/theory.md §6).

    Row k states ``u_{π(k+1)} − u_{π(k)} ≥ 0`` written in gaps:
    ``u_j − u_i = Σ_{l=i}^{j−1} γ_l`` for ``j > i`` (and minus that sum for ``j < i``).
    """
    n = len(permutation)
    H = np.zeros((n - 1, n - 1))
    for k in range(n - 1):
        i, j = permutation[k], permutation[k + 1]
        lo, hi = min(i, j), max(i, j)
        H[k, lo:hi] = 1.0 if j > i else -1.0
    return H


def gamma_map_matrix(permutation: Sequence[int]) -> FloatArray:
    """``Q_π = Wᵀ P_π R``: the linear piece of the law on ``K_π`` (docs/theory.md §6).

    Adding a constant to every velocity commutes with ``P_π`` and is annihilated by
    ``Wᵀ``, so the choice ``u_1 = 0`` in the lift ``R`` does not matter.
    """
    n = len(permutation)
    _, W, _ = chain_matrices(n)
    return W.T @ permutation_matrix(permutation) @ lift_matrix(n)


def ordering_label(permutation: Sequence[int]) -> str:
    """Readable label of the ordering, e.g. ``"u2 ≤ u1 ≤ u3"`` (1-based balls)."""
    return " ≤ ".join(f"u{i + 1}" for i in permutation)


# --------------------------------------------------------------------------- cones
@dataclass(frozen=True, eq=False)
class SectorCone:
    """One cone ``K_π`` of the sector law and its linear piece (docs/theory.md §6).

    Attributes
    ----------
    permutation : tuple of int
        0-based π; on the cone ``u_{π(0)} ≤ … ≤ u_{π(n−1)}`` and ``u⁺_k = u⁻_{π(k)}``.
    rays : ndarray, shape (n−1, n−1)
        Extreme rays (rows, unit Euclidean norm): the columns of ``H⁻¹``.
    Q : ndarray, shape (n−1, n−1)
        ``γ⁺ = Q γ⁻`` on the cone.
    inequalities : ndarray, shape (n−1, n−1)
        ``H`` with ``K = {γ : Hγ ≥ 0}``.
    label : str
        e.g. ``"u2 ≤ u1 ≤ u3"``.
    """

    permutation: tuple[int, ...]
    rays: FloatArray
    Q: FloatArray
    inequalities: FloatArray
    label: str

    def contains(self, gamma: ArrayLike, tol: float = 1e-12) -> bool | NDArray[np.bool_]:
        """Whether ``Hγ ≥ −tol·max(1, ‖γ‖)``; accepts a batch (k × (n−1))."""
        g = np.asarray(gamma, dtype=float)
        slack = g @ self.inequalities.T
        scale = np.maximum(1.0, np.linalg.norm(g, axis=-1))
        inside = np.all(slack >= -tol * scale[..., None], axis=-1)
        return bool(inside) if inside.ndim == 0 else inside


def make_cone(permutation: Sequence[int]) -> SectorCone:
    """Derive the cone, its rays and its matrix for one ordering π."""
    perm = tuple(int(p) for p in permutation)
    H = cone_inequalities(perm)
    rays = np.linalg.inv(H).T  # row k = k-th column of H⁻¹
    rays = rays / np.linalg.norm(rays, axis=1, keepdims=True)
    return SectorCone(perm, rays, gamma_map_matrix(perm), H, ordering_label(perm))


@dataclass(eq=False)
class SectorTable(PiecewiseLinearTable):
    """All n! cones of the sector law for ``n_balls`` equal balls (docs/theory.md §6).

    Attributes
    ----------
    cones : list of SectorCone
    G, W : ndarray
        Delassus matrix and contact directions (docs/theory.md §1).
    n_balls : int
    mass : float
    certificate : TableCertificate
        Exact docs/theory.md §7 certificate, computed on first access.
    """

    cones: list[SectorCone]
    G: FloatArray
    W: FloatArray
    n_balls: int
    mass: float = 1.0
    _index: dict[tuple[int, ...], int] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self._index = {c.permutation: i for i, c in enumerate(self.cones)}

    @cached_property
    def stacked_inequalities(self) -> FloatArray:
        """All ``H`` matrices stacked, shape (n_cones, n−1, n−1)."""
        return np.stack([c.inequalities for c in self.cones])

    def find_cones(self, gammas: ArrayLike, tol: float = 1e-12) -> NDArray[np.intp]:
        """Index of a cone containing each row of ``gammas`` (batch form of find_cone).

        Fast path: the stable argsort of the lifted velocities names the ordering;
        it is verified against ``H`` and, failing that, every cone is scanned.
        """
        g = np.atleast_2d(np.asarray(gammas, dtype=float))
        _check_gamma(g, self.n_balls)
        order = np.argsort(_lift(g), axis=-1, kind="stable")
        idx = np.array([self._index.get(tuple(int(p) for p in row), 0) for row in order])
        H = self.stacked_inequalities
        scale = tol * np.maximum(1.0, np.linalg.norm(g, axis=-1))
        ok = np.all(np.einsum("kij,kj->ki", H[idx], g) >= -scale[:, None], axis=-1)
        for r in np.flatnonzero(~ok):
            inside = np.all(H @ g[r] >= -scale[r], axis=-1)
            if not inside.any():
                raise SectorInputError(f"no cone of the table contains gamma={g[r]}")
            idx[r] = int(np.argmax(inside))
        return idx

    def find_cone(self, gamma: ArrayLike, tol: float = 1e-12) -> int:
        """Index in ``cones`` of a cone containing ``gamma`` (one of them on a boundary)."""
        g = np.asarray(gamma, dtype=float)
        if g.ndim != 1:
            raise SectorInputError("find_cone takes one gamma vector; use find_cones")
        return int(self.find_cones(g[None, :], tol)[0])



def sector_law_table(n_balls: int = 3, mass: float = 1.0) -> SectorTable:
    """Enumerate the n! cones of the sector law for ``n_balls`` equal balls (docs/theory.md §6).

    Parameters
    ----------
    n_balls : int
        Number of balls, 2 to 8.
    mass : float
        The common mass (positive).

    Returns
    -------
    SectorTable
        The cones with their rays, matrices Q and inequalities; ``table.certificate`` checks
        them exactly (docs/theory.md §7).

    Raises
    ------
    SectorTableTooLarge
        If ``n_balls > 8`` (use :func:`!impactqp.tables.sector_table.sector_gamma_map` instead).
    SectorInputError
        If ``n_balls < 2`` or ``mass <= 0``.
    """
    _check_balls(n_balls, mass)
    if n_balls > MAX_TABLE_BALLS:
        raise SectorTableTooLarge(
            f"sector_law_table: {n_balls} balls give {math.factorial(n_balls)} cones; "
            f"tables are built for n_balls <= {MAX_TABLE_BALLS}. "
            "Use sector_gamma_map (O(n log n), any n) to evaluate the law."
        )
    _, W, G = chain_matrices(n_balls, mass)
    return SectorTable(cones=_all_cones(n_balls, W), G=G, W=W, n_balls=n_balls,
                       mass=float(mass))


def _all_cones(n: int, W: FloatArray) -> list[SectorCone]:
    """Vectorised :func:`make_cone` over all n! orderings (same formulas, stacked)."""
    perms = np.array(list(itertools.permutations(range(n))), dtype=np.intp)
    i, j = perms[:, :-1, None], perms[:, 1:, None]
    cols = np.arange(n - 1)
    H = ((cols >= np.minimum(i, j)) & (cols < np.maximum(i, j))) * np.where(j > i, 1.0, -1.0)
    Q = W.T @ lift_matrix(n)[perms]  # Wᵀ (P_π R): row k of P_π R is row π(k) of R
    rays = np.swapaxes(np.linalg.inv(H), 1, 2)
    rays = rays / np.linalg.norm(rays, axis=2, keepdims=True)
    return [SectorCone(tuple(int(x) for x in p), r, q, h, ordering_label(p))
            for p, r, q, h in zip(perms, rays, Q, H)]


# --------------------------------------------------------------------------- maps
def sector_velocity_map(u_minus: ArrayLike) -> FloatArray:
    """Post-impact velocities of equal balls: ``u⁺ = sort(u⁻)`` ascending (docs/theory.md §6).

    A wave of neighbour swaps (elastic collisions of equal masses) sorts the
    velocities.  Works on the last axis, so a batch (k × n) is mapped row-wise.
    """
    return np.sort(np.asarray(u_minus, dtype=float), axis=-1)


def sector_gamma_map(gamma_minus: ArrayLike) -> FloatArray:
    """The sector law in gap velocities, for any number of balls, without a table (docs/theory.md
    §6).

    Lift γ to velocities by cumulative sum (``u_1 = 0``), sort, take differences:
    O(n log n).  Accepts ``(n−1,)`` or a batch ``(k, n−1)``.
    """
    g = np.asarray(gamma_minus, dtype=float)
    if g.ndim == 0 or g.shape[-1] < 1:
        raise SectorInputError("gamma_minus must have at least one gap on its last axis")
    return np.diff(np.sort(_lift(g), axis=-1), axis=-1)


# --------------------------------------------------------------------------- formatting
def _fmt(x: float) -> str:
    """A number as a fraction when it is one (denominator ≤ 1000), else ``%.6g``."""
    f = Fraction(float(x)).limit_denominator(1000)
    if abs(float(f) - x) <= 1e-9 * max(1.0, abs(x)):
        return str(f)
    return f"{x:.6g}"


def _fmt_matrix(A: FloatArray) -> str:
    return "[" + "; ".join(" ".join(_fmt(v) for v in row) for row in A) + "]"


def _fmt_ray(r: FloatArray) -> str:
    return "(" + ", ".join(_fmt(v) for v in r / np.max(np.abs(r))) + ")"


def format_sector_table(table: SectorTable, include_certificate: bool = True) -> str:
    """Plain-text table of the sector law: one row per cone (label, rays, Q).

    Rays are shown scaled to unit max-norm, matrices with exact fractions.
    With ``include_certificate`` the docs/theory.md §7 certificate summary is appended.
    """
    rows = [(c.label, " ".join(_fmt_ray(r) for r in c.rays), _fmt_matrix(c.Q))
            for c in table.cones]
    head = ("cone (ordering)", "extreme rays in γ-space", "Q  (γ⁺ = Q γ⁻)")
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(head)]
    line = "  ".join(f"{{:<{w}}}" for w in widths)
    out = [
        f"Sector law (Winandy–Leine), {table.n_balls} equal balls, m = {_fmt(table.mass)}: "
        f"u⁺ = sort(u⁻), {len(table.cones)} cones",
        f"W = {_fmt_matrix(table.W)}   G = WᵀM⁻¹W = {_fmt_matrix(table.G)}",
        "",
        line.format(*head).rstrip(),
        line.format(*("-" * w for w in widths)),
        *(line.format(*r).rstrip() for r in rows),
    ]
    if include_certificate:
        out += ["", table_report(table.certificate)]
    return "\n".join(out)


# --------------------------------------------------------------------------- helpers
def _lift(g: FloatArray) -> FloatArray:
    """Velocities ``(0, γ_1, γ_1+γ_2, …)`` along the last axis."""
    zeros = np.zeros(g.shape[:-1] + (1,))
    return np.concatenate([zeros, np.cumsum(g, axis=-1)], axis=-1)


def _check_balls(n_balls: int, mass: float) -> None:
    if not isinstance(n_balls, (int, np.integer)) or n_balls < 2:
        raise SectorInputError(f"n_balls must be an integer >= 2, got {n_balls!r}")
    if not np.isfinite(mass) or mass <= 0:
        raise SectorInputError(f"mass must be positive and finite, got {mass!r}")


def _check_gamma(g: FloatArray, n_balls: int) -> None:
    if g.ndim != 2 or g.shape[1] != n_balls - 1:
        raise SectorInputError(f"gamma must have shape (n-1,) or (k, n-1) with n-1 = "
                               f"{n_balls - 1}, got {g.shape}")
