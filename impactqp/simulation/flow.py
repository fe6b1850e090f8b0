"""The derivative of the motion (the flow) of an event-driven run (docs/theory.md §21).

Between two records the motion is linear, ẋ = Fx + c with x = (q, v), F = [[0, I], [−ΠM⁻¹K, 0]]
(Π the M-projection that holds the contacts at rest, I without), so its tangent is the state
transition matrix expm(Fτ) (exactly [[I, τI], [0, I]] under a constant force). Across an
impact triggered by contact i, with R = ∂x⁺/∂x⁻ of the impact map (velocities through the
impact's LCP tangent, positions unchanged), the tangent jumps by the saltation matrix

    S = R + (f⁺ − R f⁻) ∇gᵢᵀ / (∇gᵢ·f⁻),      ∇gᵢ·f⁻ = γᵢ⁻,

f± the vector field just before and after. An impact with γᵢ⁻ ≈ 0 is a ``"grazing"`` kink
(S = R is returned, never a division by ≈ 0), contacts settled at rest (the limit of an
accumulation of impacts) a ``"zeno"`` kink with the tangent projected onto the contacts
held, two contacts closing at one event a ``"simultaneous"`` kink.

The run is read back from its records; a contact is taken as held over an interval when it
is closed (g ≤ gap_tol) and at rest (|γ| ≤ rest_velocity) at both ends, as the integrator
holds it. A contact closed and at rest at the start is a ``"degenerate"`` kink (the
derivative with respect to data that would open or press it is one-sided). A held contact
lifts off where its force passes through zero, so the vector field is continuous there and
the tangent needs no jump.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..base.arrays import as_dense
from ..derivatives.lcp import classify, tangent
from ..laws.base import ImpactLaw
from .discrete_map import step_maps
from .sensitivity import Columns, Sensitivities, TrajectoryKink, full_restitution
from .system import LinearSystem

GRAZING = 1e-6
"""An impact whose triggering contact approaches slower than this fraction of the run's
velocity scale is grazing: its impact time is not differentiable."""


class _Motion:
    """M⁻¹, H, the force and the held projections of a system, dense."""

    def __init__(self, system: LinearSystem) -> None:
        maps, K = step_maps(system, 1.0, 0.0)  # Ŵ = M: the products of the motion
        self.system, self.n = system, system.n_dof
        self.Minv = np.linalg.inv(as_dense(system.M))
        self.MinvH, self.Ht, self.K = maps.MinvH, maps.Ht, K
        self.linear = system.linear_force is not None
        self._phi: dict[tuple, np.ndarray] = {}

    def projection(self, held: np.ndarray) -> np.ndarray:
        """Π = I − M⁻¹H_h(H_hᵀM⁻¹H_h)⁺H_hᵀ: velocities that keep the contacts ``held``."""
        idx = np.flatnonzero(held)
        if idx.size == 0:
            return np.eye(self.n)
        G = self.Ht[idx] @ self.MinvH[:, idx]
        return np.eye(self.n) - self.MinvH[:, idx] @ np.linalg.pinv(G) @ self.Ht[idx]

    def field(self, t: float, q: np.ndarray, v: np.ndarray, held: np.ndarray) -> np.ndarray:
        """f = (v, ΠM⁻¹f(t, q, v))."""
        a = self.projection(held) @ (self.Minv @ self.system.force_at(t, q, v))
        return np.concatenate([v, a])

    def transition(self, tau: float, held: np.ndarray) -> np.ndarray:
        """The state transition matrix of an interval of length ``tau``."""
        key = (tau, held.tobytes())
        if key not in self._phi:
            n = self.n
            if not self.linear:
                self._phi[key] = np.block([[np.eye(n), tau * np.eye(n)],
                                           [np.zeros((n, n)), np.eye(n)]])
            else:
                F = np.block([[np.zeros((n, n)), np.eye(n)],
                              [-self.projection(held) @ self.Minv @ self.K,
                               np.zeros((n, n))]])
                self._phi[key] = sla.expm(F * tau)
        return self._phi[key]


def flow(system: LinearSystem, law: ImpactLaw, T: np.ndarray, Q: np.ndarray, V: np.ndarray,
         L: np.ndarray, settings: dict, cols: Columns) -> Sensitivities:
    """The ``"flow"`` sensitivities of an event-driven run (docs/theory.md §21).

    Parameters
    ----------
    system, law
        Those of the run (a complementarity law).
    T, Q, V, L : ndarray
        Its records (an impact's time appears twice: before, then after).
    settings : dict
        Its settings (gap_tol, rest_velocity, tol).
    cols : Columns
    """
    motion = _Motion(system)
    n, p = system.n_dof, cols.pcols.size
    E = full_restitution(law, system.n_contacts)
    gap_tol, rest = settings["gap_tol"], settings["rest_velocity"]
    gaps = np.atleast_2d(system.gaps(Q))
    gam = np.atleast_2d(system.contact_velocities(V))
    speed = max(float(np.abs(gam).max(initial=0.0)), rest, 1e-300)
    length = max(float(np.abs(gaps).max(initial=0.0)), gap_tol, 1e-300)
    at_rest = (gaps <= gap_tol) & (np.abs(gam) <= rest)
    held = at_rest[:-1] & at_rest[1:] & (T[1:] > T[:-1])[:, None]
    turning = ((gam[:-1] < 0.0) & (gam[1:] > 0.0) & ~held).any(axis=1)
    jumps: list[np.ndarray] = []
    params: list[np.ndarray] = []
    kinks: list[TrajectoryKink] = []
    margin = np.inf
    touching = np.flatnonzero(at_rest[0])
    if touching.size:  # on the boundary at the start: moving q₀ or v₀ opens or presses them
        kinks.append(TrajectoryKink(float(T[0]), "degenerate",
                                    tuple(int(c) for c in touching), 0.0))
        margin = 0.0
    for r in range(len(T) - 1):
        if T[r + 1] > T[r]:
            for i, dist in _touches(float(T[r + 1] - T[r]), gaps[r:r + 2], gam[r:r + 2],
                                    ~held[r], length) if turning[r] else ():
                kinks.append(TrajectoryKink(float(T[r]), "grazing", (i,), dist))
                margin = min(margin, dist)
            jumps.append(motion.transition(float(T[r + 1] - T[r]), held[r]))
            params.append(np.zeros((2 * n, p)))
            continue
        J, P, found, dist = _jump(motion, r, T, Q, V, L, gaps, gam, held, E, cols,
                                  (gap_tol, rest, speed, settings["tol"]))
        jumps.append(J)
        params.append(P)
        kinks.extend(found)
        margin = min(margin, dist)
    S = np.empty((len(T),) + cols.S0.shape)
    S[0] = cols.S0
    for r, (J, P) in enumerate(zip(jumps, params)):
        S[r + 1] = J @ S[r]
        S[r + 1][:, cols.pcols] += P

    def transposed(cot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        lam, ap = cot[-1].copy(), np.zeros(p)
        for r in range(len(jumps) - 1, -1, -1):
            ap += params[r].T @ lam
            lam = jumps[r].T @ lam + cot[r]
        return lam, ap

    return Sensitivities("flow", cols, S, transposed, kinks, margin)


def _touches(tau: float, g: np.ndarray, gamma: np.ndarray, free: np.ndarray,
             length: float) -> list[tuple[int, float]]:
    """(contact, relative distance) of the free contacts whose gap comes within
    :data:`GRAZING` of the length scale between two records without closing: a grazing
    touch, found as the minimum of the cubic Hermite interpolant of (g, γ) at both ends."""
    out = []
    for i in np.flatnonzero(free & (gamma[0] < 0.0) & (gamma[1] > 0.0)):
        g0, g1, d0, d1 = g[0, i], g[1, i], gamma[0, i] * tau, gamma[1, i] * tau
        # g(s) = a s³ + b s² + d0 s + g0 on s ∈ [0, 1]; g'(s) = 3a s² + 2b s + d0
        a, b = 2.0 * (g0 - g1) + d0 + d1, 3.0 * (g1 - g0) - 2.0 * d0 - d1
        roots = np.roots([3.0 * a, 2.0 * b, d0]) if abs(a) + abs(b) > 0 else np.zeros(0)
        s = [float(x.real) for x in np.atleast_1d(roots) if abs(x.imag) < 1e-12
             and 0.0 <= x.real <= 1.0]
        low = min([g0, g1] + [((a * x + b) * x + d0) * x + g0 for x in s])
        if low <= GRAZING * length:
            out.append((int(i), float(max(low, 0.0) / length)))
    return out


def _jump(motion: _Motion, r: int, T, Q, V, L, gaps, gam, held, E, cols: Columns,
          scales: tuple[float, float, float, float],
          ) -> tuple[np.ndarray, np.ndarray, list[TrajectoryKink], float]:
    """(∂x⁺/∂x⁻, ∂x⁺/∂p, kinks, relative margin) of the event between records r and r + 1."""
    gap_tol, rest, speed, tol = scales
    n, t = motion.n, float(T[r])
    p = cols.pcols.size
    closed = gaps[r] <= gap_tol
    C = np.flatnonzero(closed)
    lam = L[r + 1, C]
    v_minus = V[r]
    kinks: list[TrajectoryKink] = []
    Rv, Pv = np.eye(n), np.zeros((n, p))
    v_plus = v_minus.copy()
    margin = np.inf
    if np.any(L[r + 1] != 0.0):
        G = motion.Ht[C] @ motion.MinvH[:, C]
        ECC = E[np.ix_(C, C)]
        q_imp = (np.eye(C.size) + ECC) @ gam[r, C]
        aset = classify(lam * np.diag(G), G @ lam + q_imp, tol * speed)
        margin = aset.margin / speed
        if aset.degenerate.any():
            kinks.append(TrajectoryKink(t, "degenerate",
                                        tuple(int(c) for c in C[aset.degenerate]), 0.0))
        Tn = tangent(G, lam, aset, dq=np.eye(C.size))
        Rv = Rv + motion.MinvH[:, C] @ Tn @ (np.eye(C.size) + ECC) @ motion.Ht[C]
        if p:
            Rdir = np.stack([d[np.ix_(C, C)] @ gam[r, C] for d in cols.directions], axis=1)
            Pv = motion.MinvH[:, C] @ Tn @ Rdir
        v_plus = v_minus + motion.MinvH[:, C] @ lam
    settle = closed & (motion.Ht @ v_plus <= rest)
    Pi = np.eye(n)
    if settle.any() and not np.allclose(V[r + 1], v_plus, rtol=1e-12, atol=1e-12 * speed):
        Pi = motion.projection(settle)  # held at rest: the end of an accumulation
        kinks.append(TrajectoryKink(t, "zeno", tuple(int(c) for c in np.flatnonzero(settle)),
                                    0.0))
        margin = 0.0
    R = np.block([[Pi, np.zeros((n, n))], [np.zeros((n, n)), Pi @ Rv]])
    P = np.vstack([np.zeros((n, p)), Pi @ Pv])
    before = r - 1 if r > 0 and T[r - 1] < T[r] else None
    opened = gaps[before] > gap_tol if before is not None else np.zeros_like(closed)
    trigger = np.flatnonzero(closed & opened & (gam[r] < 0.0))
    if trigger.size > 1:
        kinks.append(TrajectoryKink(t, "simultaneous", tuple(int(c) for c in trigger), 0.0))
        margin = 0.0
    if trigger.size:
        i = int(trigger[np.argmin(gam[r, trigger])])
        approach = float(gam[r, i])
        if abs(approach) <= GRAZING * speed:
            kinks.append(TrajectoryKink(t, "grazing", (i,), abs(approach) / speed))
            margin = min(margin, abs(approach) / speed)
        else:
            after = held[r + 1] if r + 1 < len(held) else np.zeros_like(closed)
            f_minus = motion.field(t, Q[r], v_minus, held[before] if before is not None
                                   else np.zeros_like(closed))
            f_plus = motion.field(t, Q[r + 1], V[r + 1], after)
            grad = np.concatenate([motion.Ht[i], np.zeros(n)])
            R = R + np.outer(f_plus - R @ f_minus, grad) / approach
    return R, P, kinks, margin
