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

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_dense
from ..derivatives.lcp import classify, tangent
from ..kernels.sensitivity import StepMaps, StepTangents, adjoint, forward
from ..laws.base import ImpactLaw
from .sensitivity import Columns, Sensitivities, TrajectoryKink, full_restitution
from .system import LinearSystem


def _dense(A) -> np.ndarray:
    return A.toarray() if sp.issparse(A) else np.asarray(A, dtype=float)


def step_maps(system: LinearSystem, h: float, theta: float) -> tuple[StepMaps, np.ndarray,
                                                                       np.ndarray]:
    """(the shared parts of the step tangent, Ŵ = M + h²θ²K, K) for a constant or a linear
    force (a callable one is refused by :func:`.through_time.check`)."""
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
    return maps, What, K


def free_velocities(system: LinearSystem, What: np.ndarray, K: np.ndarray, h: float,
                    theta: float, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
    """v_free of every step from the rows (q_k, v_k) (docs/theory.md §14, step 2)."""
    if system.linear_force is not None:
        c = system.linear_force.constant
        r = h * (Q @ K.T) + (h * h * theta) * (V @ K.T) - h * c
    else:
        r = np.broadcast_to(-h * system.constant_force, V.shape)
    return V - np.linalg.solve(What, r.T).T


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
    h, theta, tol, t0 = settings["h"], settings["theta"], settings["tol"], settings["t0"]
    maps, What, K = step_maps(system, h, theta)
    E = full_restitution(law, system.n_contacts)
    Gfull = maps.Ht @ maps.MinvH
    Qk, Vk = Q[:-1], V[:-1]
    gaps = np.atleast_2d(system.gaps(Qk))
    gam = np.atleast_2d(system.contact_velocities(Vk))
    predicted = gaps + (0.5 * h) * gam
    closed = predicted <= 0.0
    length = max(float(np.abs(gaps).max(initial=0.0)),
                 h * float(np.abs(gam).max(initial=0.0)), 1e-300)
    kinks: list[TrajectoryKink] = []
    margin = float(np.abs(predicted).min(initial=np.inf)) / length
    near = np.argwhere(np.abs(predicted) <= tol * length)
    for k, i in near:
        kinks.append(TrajectoryKink(float(t0 + k * h), "activation", (int(i),),
                          float(abs(predicted[k, i])) / length))
    VF = free_velocities(system, What, K, h, theta, Qk, Vk)
    rows = _Rows(len(cols.pcols))
    for k in np.flatnonzero(closed.any(axis=1)):
        C = np.flatnonzero(closed[k])
        G = Gfull[np.ix_(C, C)]
        lam = L[k + 1, C]
        gamma_k = gam[k, C]
        q_step = maps.Ht[C] @ VF[k] + E[np.ix_(C, C)] @ gamma_k
        speed = max(float(np.abs(q_step).max()), float(np.abs(gamma_k).max()), 1e-300)
        aset = classify(lam * np.diag(G), G @ lam + q_step, tol * speed)
        margin = min(margin, aset.margin / speed)
        if aset.degenerate.any():
            kinks.append(TrajectoryKink(float(t0 + (k + 1) * h), "degenerate",
                              tuple(int(c) for c in C[aset.degenerate]), 0.0))
        if not aset.active.any():
            continue
        T = tangent(G, lam, aset, dq=np.eye(C.size))
        R = np.stack([d[np.ix_(C, C)] @ gamma_k for d in cols.directions], axis=1) \
            if cols.pcols.size else np.zeros((C.size, 0))
        rows.add(k, C, T, T @ E[np.ix_(C, C)], T @ R)
    tangents = rows.arrays(cols.pcols)
    out = np.empty((Q.shape[0],) + cols.S0.shape)
    forward(maps, tangents, np.ascontiguousarray(cols.S0), out)

    def transposed(cot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return adjoint(maps, tangents, np.ascontiguousarray(cot))

    return Sensitivities("discrete-map", cols, out, transposed, kinks, margin)


class _Rows:
    """The steps with a non-zero LCP tangent, gathered into :class:`StepTangents`."""

    def __init__(self, p: int) -> None:
        self.p = p
        self.steps: list[int] = []
        self.contacts: list[np.ndarray] = []
        self.Ta: list[np.ndarray] = []
        self.Tb: list[np.ndarray] = []
        self.Tp: list[np.ndarray] = []

    def add(self, k: int, C: np.ndarray, Ta: np.ndarray, Tb: np.ndarray,
            Tp: np.ndarray) -> None:
        self.steps.append(int(k))
        self.contacts.append(C)
        self.Ta.append(Ta.ravel())
        self.Tb.append(Tb.ravel())
        self.Tp.append(Tp.ravel())

    def arrays(self, pcols: np.ndarray) -> StepTangents:
        sizes = np.array([c.size for c in self.contacts], dtype=np.int64)

        def flat(parts: list[np.ndarray], dtype: type) -> np.ndarray:
            return np.ascontiguousarray(np.concatenate(parts) if parts else np.zeros(0),
                                        dtype=dtype)

        return StepTangents(np.array(self.steps, dtype=np.int64),
                            np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
                            flat(self.contacts, np.int64), flat(self.Ta, float),
                            flat(self.Tb, float),
                            np.concatenate([[0], np.cumsum(sizes ** 2)]).astype(np.int64),
                            flat(self.Tp, float), np.ascontiguousarray(pcols, dtype=np.int64))
