"""Smooth motion between impacts (docs/theory.md §14): free contacts watched for closing,
closed contacts held as bilateral constraints while they push, watched for lift-off.

With the contacts B held closed (Hᵀ_B a = 0) the acceleration is

    a = M⁻¹(f + H_B λ),    G_BB λ = −H_Bᵀ M⁻¹ f,    G_BB = H_BᵀM⁻¹H_B,

and which closed contacts stay closed is decided by the acceleration LCP
``0 ≤ λ ⟂ Hᵀa ≥ 0``: the impact problem (M, H_C, u⁻ = M⁻¹f) under Moreau's law with ε = 0,
whose u⁺ is a and whose impulses are λ.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..base.arrays import as_dense
from ..errors import SolverError
from ..laws.moreau import Moreau
from ..laws.pipeline import solve
from ..model.problem import ImpactProblem
from ..model.structure import ImpactStructure
from .clusters import ClusterCache
from .system import LinearSystem

PLASTIC = Moreau(0.0)


def contact_accelerations(system: LinearSystem, cache: ClusterCache, t: float, q: np.ndarray,
                          v: np.ndarray, closed: np.ndarray,
                          tol: float) -> tuple[np.ndarray, np.ndarray]:
    """(a, λ over all contacts): the acceleration LCP over the closed contacts, solved per
    cluster as a certified impact problem with ε = 0."""
    a = system.structure.solve_mass(system.force_at(t, q, v))
    lam = np.zeros(system.n_contacts)
    if not closed.any():
        return a, lam
    out = a.copy()
    for cl in cache.clusters(closed):
        result = solve(ImpactProblem.from_structure(cl.structure, a[cl.dofs]), PLASTIC, tol=tol)
        out[cl.dofs] = result.u_plus
        lam[cl.contacts] = result.impulses
    return out, lam


class Phase:
    """The dynamics of one smooth phase with the contacts ``held`` closed.

    Parameters
    ----------
    system : LinearSystem
    held : ndarray of bool
        Contacts kept closed (bilateral) during the phase.
    structures : dict
        Cache of ImpactStructure per frozenset of held contacts (shared across phases).
    """

    def __init__(self, system: LinearSystem, held: np.ndarray,
                 structures: dict[frozenset, tuple]) -> None:
        self.system = system
        self.n = system.n_dof
        self.held = np.flatnonzero(held)
        key = frozenset(self.held.tolist())
        if key not in structures and self.held.size:
            H = system.H[:, self.held]
            st = ImpactStructure(system.M, H)
            structures[key] = (st, self._factor(st))
        self._st, self._factor_G = structures.get(key, (None, None))

    @staticmethod
    def _factor(st: ImpactStructure) -> Callable[[np.ndarray], np.ndarray]:
        """A solver for G_BB x = r (least squares when contacts are redundant)."""
        G = st.delassus
        if sp.issparse(G) and st.delassus_lu is not None:
            return st.delassus_lu.solve
        G = as_dense(G)
        try:
            c = sla.cho_factor(G)
            if np.linalg.cond(G) < 1e12:
                return lambda r: sla.cho_solve(c, r)
        except np.linalg.LinAlgError:
            pass
        pinv = np.linalg.pinv(G)
        return lambda r: pinv @ r

    def acceleration(self, t: float, q: np.ndarray, v: np.ndarray,
                     ) -> tuple[np.ndarray, np.ndarray]:
        """(a, λ of the held contacts)."""
        f = self.system.force_at(t, q, v)
        a = self.system.structure.solve_mass(f)
        if self._st is None:
            return a, np.zeros(0)
        lam = -self._factor_G(self._st.Wt_times(a))
        return a + self._st.impulse_velocity(lam), lam

    def hold(self, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(v projected onto Hᵀ_B v = 0 in the metric M, the impulses doing it)."""
        if self._st is None:
            return v, np.zeros(0)
        lam = -self._factor_G(self._st.Wt_times(v))
        return v + self._st.impulse_velocity(lam), lam

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        q, v = y[:self.n], y[self.n:]
        return np.concatenate([v, self.acceleration(t, q, v)[0]])

    def closing_event(self, watched: np.ndarray, near: np.ndarray,
                      g0: np.ndarray) -> Callable[[float, np.ndarray], float]:
        """min over the watched contacts of their gap (of gᵢ − gᵢ(t₀) for those ``near``
        closed at the start, which are 0 there and positive once they separate): falls
        through zero when the first of them closes."""
        H = self.system.Ht[watched]
        offset = self.system.b[watched] - np.where(near, g0, 0.0)
        if H.shape[0] == 0:
            def never(t: float, y: np.ndarray) -> float:
                return 1.0
            return _terminal(never)

        def closing(t: float, y: np.ndarray) -> float:
            return float(np.min(H @ y[:self.n] + offset))
        return _terminal(closing)

    def liftoff_event(self, threshold: float) -> Callable[[float, np.ndarray], float]:
        """min over the held contacts of λ + threshold: falls through zero when one of
        them would need to pull."""
        if self._st is None:
            def never(t: float, y: np.ndarray) -> float:
                return 1.0
            return _terminal(never)

        def liftoff(t: float, y: np.ndarray) -> float:
            lam = self.acceleration(t, y[:self.n], y[self.n:])[1]
            return float(np.min(lam) + threshold)
        return _terminal(liftoff)


def first_closing(g: np.ndarray, gamma: np.ndarray, alpha: np.ndarray,
                  near: np.ndarray) -> float:
    """The first τ > 0 at which a gap gᵢ(τ) = gᵢ + γᵢτ + ½αᵢτ² falls through zero, ∞ if none
    does (docs/theory.md §14, phases under a constant force).

    A gap that is ``near`` closed at the start is watched as gᵢ(τ) − gᵢ(0) (as the closing
    event of :class:`Phase`): it closes at τ = −2γᵢ/αᵢ when it separates and decelerates, at
    once when it approaches.
    Otherwise the falling root, where γᵢ + αᵢτ = −√D with D = γᵢ² − 2αᵢgᵢ, is taken in the form
    without cancellation: 2gᵢ/(−γᵢ + √D) when γᵢ < 0, (−γᵢ − √D)/αᵢ when γᵢ ≥ 0 (then only
    αᵢ < 0 brings the gap back).
    """
    tau = np.where(near & (gamma < 0), 0.0, np.inf)  # closing at once (a law left γ⁺ < 0)
    back = near & (gamma > 0) & (alpha < 0)
    tau[back] = -2.0 * gamma[back] / alpha[back]
    far = ~near
    D = gamma * gamma - 2.0 * alpha * np.where(far, g, 0.0)
    approaching = far & (gamma < 0) & (D >= 0)
    tau[approaching] = 2.0 * g[approaching] / (-gamma[approaching] + np.sqrt(D[approaching]))
    returning = far & (gamma >= 0) & (alpha < 0)
    tau[returning] = (-gamma[returning] - np.sqrt(D[returning])) / alpha[returning]
    return float(np.min(tau, initial=np.inf))


def _terminal(fn: Callable[[float, np.ndarray], float]) -> Callable[[float, np.ndarray], float]:
    fn.terminal = True
    fn.direction = -1.0
    return fn


def check_solved(status: int, message: str, t: float) -> None:
    """Raise SolverError when scipy's integrator failed."""
    if status < 0:
        raise SolverError(f"the ODE integrator failed at t = {t:.12g}: {message}")
