"""The exact derivative of a Moreau–Jean run's discrete map (docs/theory.md §21).

Each step is differentiated on what it did: the contacts it closed (the activation
g + ½hγ ≤ 0, constant near the run unless a contact sits on the threshold, where the map
jumps: an ``"activation"`` kink) and the active set of its LCP
``w = G_CC Λ + H_Cᵀv_free + E_CC H_Cᵀv_k`` (tangent by :func:`impactqp.derivatives.lcp.tangent`,
a ``"degenerate"`` kink where Λᵢ = 0 = wᵢ). The steps are read back from the recorded run
(every step's q, v and Λ), so the compiled and the Python loop are differentiated alike,
and chained by :mod:`impactqp.kernels.sensitivity`.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_dense
from ..derivatives.lcp import ActiveSet, classify, tangent
from ..kernels.sensitivity import StepMaps, StepTangents, adjoint, forward
from ..kernels.step import activation, gap_ahead
from ..laws.base import ImpactLaw
from .sensitivity import Columns, Sensitivities, TrajectoryKink, full_restitution
from .system import LinearSystem


def _dense(A) -> np.ndarray:
    return A.toarray() if sp.issparse(A) else np.asarray(A, dtype=float)


def step_maps(system: LinearSystem, h: float, theta: float) -> tuple[StepMaps, np.ndarray]:
    """(the shared parts of the step tangent with Ŵ = M + h²θ²K, K) for a constant or a
    linear force (a callable one is refused by :func:`.through_time.check`)."""
    n = system.n_dof
    M = as_dense(system.M)
    Hn = _dense(system.H)
    lin = system.linear_force
    K = np.zeros((n, n)) if lin is None else _dense(lin.stiffness)
    What = M + (h * theta) ** 2 * K
    MinvH = np.linalg.solve(What, Hn)
    Fq = -h * np.linalg.solve(What, K)
    Fv = np.eye(n) + h * theta * Fq
    maps = StepMaps(np.ascontiguousarray(Fq), np.ascontiguousarray(Fv), lin is not None,
                    float(h), float(theta), np.ascontiguousarray(MinvH),
                    np.ascontiguousarray(Hn.T))
    return maps, K


class Run(NamedTuple):
    """What the steps of a recorded run are differentiated from.

    Attributes
    ----------
    L : (steps + 1, columns of H) ndarray
        The impulses of the step ending at each record.
    gam : (steps + 1, m) ndarray
        The normal velocities γ_k at each record.
    VF : (steps, n) ndarray
        v_free of each step, v_{k+1} − Ŵ⁻¹HΛ as the step computed it.
    tol : float
        The run's certificate tolerance: quantities within it of a kink are on it.
    """

    L: np.ndarray
    gam: np.ndarray
    VF: np.ndarray
    tol: float


Flagged = tuple[str, np.ndarray, np.ndarray, np.ndarray]
"""(kind, steps K, contacts C, (|K|, |C|) bool mask of the contacts on the kink)."""

Group = Callable[[np.ndarray, np.ndarray, Run], tuple[list, float, list[Flagged]]]
"""The tangents of the steps K that close the contacts C: (parts for :func:`_stack`, the
smallest relative margin, the kinks found)."""


def discrete_map(system: LinearSystem, law: ImpactLaw, Q: np.ndarray, V: np.ndarray,
                 L: np.ndarray, settings: dict, cols: Columns) -> Sensitivities:
    """The ``"discrete-map"`` sensitivities of a Moreau–Jean run recorded at every step
    (docs/theory.md §21).

    Parameters
    ----------
    system, law
        Those of the run (a complementarity law: Moreau, Newton, Frémond).
    Q, V, L : (steps + 1, ·) ndarray
        The run's positions, velocities and impulses, one row per step.
    settings : dict
        The run's settings (h, θ, tol, t0).
    cols : Columns
        What the tangents are taken with respect to.
    """
    maps, _ = step_maps(system, settings["h"], settings["theta"])
    E = full_restitution(law, system.n_contacts)
    group = partial(_group, maps.Ht @ maps.MinvH, maps.Ht, E, cols)
    return chained(system, maps, Q, V, L, settings, cols, group)


def chained(system: LinearSystem, maps: StepMaps, Q: np.ndarray, V: np.ndarray,
            L: np.ndarray, settings: dict, cols: Columns, group: Group, *,
            dofs: bool = False) -> Sensitivities:
    """The steps of a recorded run differentiated by ``group`` (the steps closing one set
    of contacts at a time) and chained by :mod:`impactqp.kernels.sensitivity`, with the
    activation kinks of every step (docs/theory.md §21).

    ``dofs``: the groups give each step's tangent in the degrees of freedom rather than in
    the rows of H (Ŵ⁻¹H_C T H_Cᵀ in place of T, "contacts" 0 … n − 1), which the chain
    then reads with Ŵ⁻¹H and Hᵀ replaced by the identity: cheaper when a step closes more
    rows than the system has degrees of freedom."""
    h, tol, t0 = settings["h"], settings["tol"], settings["t0"]
    gaps = np.atleast_2d(system.gaps(Q[:-1]))
    gam = np.atleast_2d(system.contact_velocities(V))
    predicted = gap_ahead(gaps, gam[:-1], h)  # the activation rule's own quantity
    closed = np.empty(gaps.size, dtype=bool)
    activation(np.ascontiguousarray(gaps).ravel(), np.ascontiguousarray(gam[:-1]).ravel(), h,
               closed)
    closed = closed.reshape(gaps.shape)
    length = max(float(np.abs(gaps).max(initial=0.0)),
                 h * float(np.abs(gam[:-1]).max(initial=0.0)), 1e-300)
    margin = float(np.abs(predicted).min(initial=np.inf)) / length
    near = np.argwhere(np.abs(predicted) <= tol * length)
    found: list[tuple] = [(near[:, 0], near[:, 1], np.abs(predicted[near[:, 0], near[:, 1]])
                           / length)]
    run = Run(L, gam, V[1:] - L[1:] @ maps.MinvH.T, tol)
    steps = np.flatnonzero(closed.any(axis=1))
    parts = []
    if steps.size:
        patterns, which = _patterns(closed[steps])
        for g, mask in enumerate(patterns):  # the steps that close the same contacts
            part, low, flagged = group(steps[which == g], np.flatnonzero(mask), run)
            parts.extend(part)
            margin = min(margin, low)
            found.extend(flagged)
    tangents = _stack(parts, cols.pcols)
    if dofs:
        eye = np.eye(system.n_dof)
        maps = maps._replace(MinvH=eye, Ht=eye)
    out = np.empty((Q.shape[0],) + cols.S0.shape)
    forward(maps, tangents, np.ascontiguousarray(cols.S0), out)

    def transposed(cot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return adjoint(maps, tangents, np.ascontiguousarray(cot))

    def kinks() -> list[TrajectoryKink]:
        steps_, contacts_, distances = found[0]
        listed = [TrajectoryKink(float(t0 + k * h), "activation", (int(i),), float(d))
                  for k, i, d in zip(steps_, contacts_, distances)]
        for kind, K, C, masks in found[1:]:
            listed += [TrajectoryKink(float(t0 + (k + 1) * h), kind,
                                      tuple(int(c) for c in C[row]), 0.0)
                       for k, row in zip(K, masks) if row.any()]
        return sorted(listed, key=lambda kink: kink.time)

    return Sensitivities("discrete-map", cols, out, transposed, kinks, margin)


def _group(Gfull: np.ndarray, Ht: np.ndarray, E: np.ndarray, cols: Columns, K: np.ndarray,
           C: np.ndarray, run: Run) -> tuple[list, float, list[Flagged]]:
    """The LCP tangents of the steps K that close the contacts C, one per active set
    (T depends on the active set only), the smallest relative margin and the degenerate
    steps."""
    L, gam, VF, tol = run
    G, ECC = Gfull[np.ix_(C, C)], E[np.ix_(C, C)]
    lam, gamma_k = L[K + 1][:, C], gam[K][:, C]
    q_step = VF[K] @ Ht[C].T + gamma_k @ ECC.T
    speed = np.maximum(np.maximum(np.abs(q_step).max(axis=1), np.abs(gamma_k).max(axis=1)),
                       1e-300)[:, None]
    # velocity units relative to each step's speed: ΛᵢGᵢᵢ and wᵢ
    aset = classify((lam * np.diag(G)) / speed, (lam @ G + q_step) / speed, tol)
    active = aset.active.reshape(lam.shape)
    degenerate = aset.degenerate.reshape(lam.shape)
    R = np.einsum("jab,sb->saj", cols.directions[:, C][:, :, C], gamma_k)
    parts = []
    pressed = active.any(axis=1)
    if pressed.any():
        sets, which = _patterns(active[pressed])
        for a, mask in enumerate(sets):
            rows = np.flatnonzero(pressed)[which == a]
            T = tangent(G, lam[rows[0]], ActiveSet(mask, np.zeros_like(mask), aset.margin),
                        dq=np.eye(C.size))
            parts.append((K[rows], C, T, T @ ECC, np.einsum("ab,sbj->saj", T, R[rows])))
    return parts, aset.margin, [("degenerate", K, C, degenerate)]


def _patterns(rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(the distinct rows of a boolean (s, m) array, the index of each row among them), by
    each row's bits as one integer when m ≤ 62."""
    if rows.shape[1] > 62:
        patterns, which = np.unique(rows, axis=0, return_inverse=True)
        return patterns, which.ravel()
    codes = rows @ (np.int64(1) << np.arange(rows.shape[1], dtype=np.int64))
    _, first, which = np.unique(codes, return_index=True, return_inverse=True)
    return rows[first], which.ravel()


def _stack(parts: list, pcols: np.ndarray) -> StepTangents:
    """The groups' tangents as one :class:`StepTangents`, in step order, padded."""
    count = sum(p[0].size for p in parts)
    width = max((p[1].size for p in parts), default=0)
    steps = np.zeros(count, dtype=np.int64)
    sizes = np.zeros(count, dtype=np.int64)
    contacts = np.zeros((count, width), dtype=np.int64)
    Ta, Tb = np.zeros((count, width, width)), np.zeros((count, width, width))
    Tp = np.zeros((count, width, pcols.size))
    row = 0
    for K, C, T, TE, TR in parts:
        rows, c = slice(row, row + K.size), C.size
        steps[rows], sizes[rows], contacts[rows, :c] = K, c, C
        Ta[rows, :c, :c], Tb[rows, :c, :c], Tp[rows, :c] = T, TE, TR
        row += K.size
    order = np.argsort(steps, kind="stable")
    return StepTangents(steps[order], sizes[order], np.ascontiguousarray(contacts[order]),
                        np.ascontiguousarray(Ta[order]), np.ascontiguousarray(Tb[order]),
                        np.ascontiguousarray(Tp[order]),
                        np.ascontiguousarray(pcols, dtype=np.int64))
