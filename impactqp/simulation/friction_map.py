"""The exact derivative of a frictional Moreau–Jean run's discrete map (docs/theory.md §21).

A frictional step (docs/theory.md §17) solves, on the contacts C it closes, the local problem
U = Wr + q, W = H_CᵀŴ⁻¹H_C, q = H_Cᵀv_free + eγ_k (normal rows), under Coulomb's law with
μ. Each closed contact of the recorded answer is in one mode — separated, sticking or
sliding — and the mode's equations F(r, U, μ) = 0
(:func:`impactqp.derivatives.coulomb.mode_equations`, the single impact's) give, by the
implicit function theorem, dr = T dq + T_μ dμ with T = −J⁻¹F_U, T_μ = −J⁻¹F_μ and
J = F_r + F_U W; T and T_μ enter the chain of :mod:`impactqp.kernels.sensitivity` where a
frictionless step puts its LCP tangent, with E the restitution on the normal rows and one
more parameter term for μ. The modes are read in contact units (r̃ = sr, Ũ = U/s, s² the
normal diagonal entry of W, docs/theory.md §16) relative to each step's speed; a contact
within the run's ``tol`` of a change of mode is a kink: ``"degenerate"`` (Λ_n = 0 = U_n)
or ``"stick-slide"`` (‖Λ_T‖ = μΛ_n with U_T = 0), and the tangent returned is that of the
mode it was read in.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from ..derivatives.coulomb import SEPARATE, SLIDE, STICK, mode_equations
from ..laws.base import ImpactLaw
from .discrete_map import Flagged, Run, chained, step_maps
from .friction_step import coulomb_coefficients
from .sensitivity import Columns, Sensitivities
from .system import LinearSystem

SINGULAR = 1e-12
"""Singular values of a step's J (in contact units) below this fraction of its largest are
dropped: redundant contacts (a box on four corners) leave the impulses' derivative
undetermined along null(J), and the minimum-norm one is returned."""

LOOSE = 1e-6
"""A step whose null(J) moves the velocities (‖Ŵ⁻¹H_C n‖ above this fraction of
‖Ŵ⁻¹H_C‖ in contact units) is ``"indeterminate"``: its impulses, and with them v_{k+1}, are
not fixed by the law (a box sliding and spinning on four corners distributes its weight as
the solver does), so the derivative returned is one of many."""


def frictional_map(system: LinearSystem, law: ImpactLaw, Q: np.ndarray, V: np.ndarray,
                   L: np.ndarray, settings: dict, cols: Columns) -> Sensitivities:
    """The ``"discrete-map"`` sensitivities of a frictional Moreau–Jean run recorded at
    every step (docs/theory.md §21).

    Parameters
    ----------
    system : LinearSystem
        With ``contact_dim`` 2 or 3.
    law : Coulomb
    Q, V, L : (steps + 1, ·) ndarray
        The run's positions, velocities and impulses (every column of H), one row per step.
    settings : dict
        The run's settings (h, θ, tol, t0).
    cols : Columns
        What the tangents are taken with respect to (``"mu"`` and ``"restitution"`` among
        them).
    """
    maps, _ = step_maps(system, settings["h"], settings["theta"])
    mu, e = coulomb_coefficients(law, system)
    dofs = system.H.shape[1] > system.n_dof  # more rows than dofs: chain in the dofs
    group = partial(_steps, maps.Ht, maps.MinvH, (mu, e, system.contact_dim), cols, dofs)
    return chained(system, maps, Q, V, L, settings, cols, group, dofs=dofs)


def _steps(Ht: np.ndarray, MinvH: np.ndarray, law: tuple, cols: Columns, dofs: bool,
           K: np.ndarray, C: np.ndarray, run: Run) -> tuple[list, float, list[Flagged]]:
    """The tangents of the steps K that close the contacts C, one per step (in the rows of
    H, or in the dofs with ``dofs``: see :func:`.discrete_map.chained`), the smallest
    relative margin and the contacts on a kink."""
    mu_all, e_all, d = law
    L, gam, VF, tol = run
    rows = (C[:, None] * d + np.arange(d)).ravel()
    W = Ht[rows] @ MinvH[:, rows]
    W = 0.5 * (W + W.T)
    mu, e = mu_all[C], e_all[C]
    r, gamma_k = L[K + 1][:, rows], gam[K][:, C]
    q = VF[K] @ Ht[rows].T
    q[:, ::d] += e * gamma_k
    U = r @ W + q
    s = np.repeat(np.sqrt(np.maximum(np.diag(W)[::d], 1e-300)), d)  # contact units per row
    speed = np.maximum(np.maximum(np.abs(q).max(axis=1), np.abs(gamma_k).max(axis=1)),
                       1e-300)[:, None]
    modes, flagged, margin = _modes(r * s, U / s, mu, d, speed / s[::d], tol)
    FL, FU, Fmu = mode_equations(modes, r * s, U / s, mu, d)
    inverse, loose = _inverse(FL + FU @ (W / np.outer(s, s)), MinvH[:, rows] / s)
    flagged["indeterminate"] = np.repeat(loose[:, None], C.size, axis=1)
    if loose.any():
        margin = 0.0
    X = -inverse @ np.concatenate([FU, Fmu], axis=2)
    T = X[:, :, :rows.size] / np.outer(s, s)  # back from contact units: T = D T̃ D
    Tmu = X[:, :, rows.size:] / s[:, None]
    R = np.einsum("jab,sb->saj", cols.directions[:, C][:, :, C], gamma_k)
    Tp = T[:, :, ::d] @ R + Tmu @ cols.mu_directions[:, C].T
    e_rows = np.zeros(rows.size)
    e_rows[::d] = e
    parts = [(K, rows, T, T * e_rows, Tp)]
    if dofs:
        Y, Hr = MinvH[:, rows], Ht[rows]
        parts = [(K, np.arange(Y.shape[0]), Y @ T @ Hr, Y @ (T * e_rows) @ Hr, Y @ Tp)]
    return parts, margin, [(kind, K, C, mask) for kind, mask in flagged.items()]


def _inverse(J: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(J⁺ of each step, whether null(J) moves the velocities Y·n), by one SVD per step."""
    left, sigma, right = np.linalg.svd(J)
    keep = sigma > SINGULAR * sigma[:, :1]
    inv = np.divide(1.0, sigma, out=np.zeros_like(sigma), where=keep)
    inverse = np.transpose(right, (0, 2, 1)) * inv[:, None, :] @ np.transpose(left, (0, 2, 1))
    null = np.transpose(right, (0, 2, 1)) * ~keep[:, None, :]
    moved = np.linalg.norm(Y @ null, axis=1).max(axis=1, initial=0.0)
    return inverse, moved > LOOSE * np.linalg.norm(Y, 2)


def _modes(r: np.ndarray, U: np.ndarray, mu: np.ndarray, d: int, speed: np.ndarray,
           tol: float) -> tuple[np.ndarray, dict[str, np.ndarray], float]:
    """(the mode of each step's contacts (s, |C|), the contacts on a kink by kind, the
    smallest relative distance to one) from r and U in contact units, relative to each
    step's speed in the same units ((s, |C|): velocities over s)."""
    rn, un = r[:, ::d] / speed, U[:, ::d] / speed
    rt = np.linalg.norm(r.reshape(r.shape[0], -1, d)[:, :, 1:], axis=2) / speed
    ut = np.linalg.norm(U.reshape(U.shape[0], -1, d)[:, :, 1:], axis=2) / speed
    separate = rn <= tol
    stick = ~separate & (ut <= tol) & (mu > 0)
    slide = ~separate & ~stick
    edge = mu * rn - rt
    flagged = {"degenerate": separate & (un <= tol), "stick-slide": stick & (edge <= tol)}
    distances = np.concatenate([
        un[separate & ~flagged["degenerate"]],
        rn[~separate], edge[stick & ~flagged["stick-slide"]],
        ut[slide & (mu > 0)]])
    margin = float(distances.min(initial=np.inf))
    if any(mask.any() for mask in flagged.values()):
        margin = 0.0
    modes = np.where(separate, SEPARATE, np.where(stick, STICK, SLIDE))
    return modes, flagged, margin
