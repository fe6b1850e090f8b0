"""The derivative of Coulomb's law of frictional impacts (docs/theory.md §16, §18–§19).

Each contact is in one mode: separated (Λ_c = 0, U_n > 0), sticking (Λ_c inside the cone,
U_c = 0) or sliding (U_n = 0, U_T ≠ 0, Λ_T = −μΛ_n t with t = U_T/‖U_T‖). With
U = GΛ + q and q = (I + E)Wᵀu⁻ (E: the restitution on the normal rows), the mode's equations
F(Λ, U, μ) = 0 are smooth, and the implicit function theorem gives

    dΛ = −J⁻¹(F_U r + F_μ dμ),   J = F_Λ + F_U G,   r = dG Λ + dq,

the same r as the frictionless laws (docs/theory.md §18). ∂/∂μ is exactly 0 for sticking
and separated contacts (μ enters only the sliding equations). Kinks: contact ↔ separation
(Λ_n = 0 = U_n) and stick ↔ slide (‖Λ_T‖ = μΛ_n with U_T = 0).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from functools import cached_property
from typing import Any

import numpy as np

from ..errors import NoSolutionError
from ..laws.friction import solve_friction
from ..model.friction import FrictionContactProblem
from .complementarity import ComplementarityMap, Parameter
from .local import Kink, LocalMap

SEPARATE, STICK, SLIDE, ONSET = 0, 1, 2, 3
"""Contact modes; ONSET is sliding that starts at the answer (U_T = 0 on the cone's edge)."""


def normal_rows(name: str, value: np.ndarray, nc: int, d: int) -> Parameter:
    """E = diag of the restitution on the normal rows (one number, or one per contact)."""
    m = nc * d

    def to_E(p: np.ndarray) -> np.ndarray:
        E = np.zeros((m, m))
        E[np.arange(0, m, d), np.arange(0, m, d)] = np.broadcast_to(p, (nc,))
        return E

    def cotangent(Ebar: np.ndarray) -> np.ndarray:
        diag = Ebar[:, np.arange(0, m, d), np.arange(0, m, d)]
        return diag if np.ndim(value) else diag.sum(axis=1)

    return Parameter(name, np.asarray(value, dtype=float).copy(), to_E, cotangent)


class CoulombMap(ComplementarityMap):
    """Coulomb's local map at one answer (docs/theory.md §18–§19).

    Parameters
    ----------
    M, W, u_minus, impulses
        As for :class:`~impactqp.derivatives.complementarity.ComplementarityMap`.
    d : int
        Columns of W per contact (2 or 3).
    mu : ndarray
        μ as the law holds it (0-d or one per contact).
    restitution : Parameter
    kink_tol : float
    evaluate : callable
        data ↦ (u⁺, Λ) of the law at other inputs (audits).
    """

    def __init__(self, M: Any, W: Any, u_minus: np.ndarray, impulses: np.ndarray, *, d: int,
                 mu: np.ndarray, restitution: Parameter, kink_tol: float,
                 evaluate: Callable[[dict], tuple[np.ndarray, np.ndarray]]) -> None:
        s, V = self._setup(M, W, u_minus, impulses, restitution)
        self.d, self.mu_value, self._evaluate = d, np.asarray(mu, dtype=float), evaluate
        nc = self.W.shape[1] // d
        self.mu = np.broadcast_to(self.mu_value, (nc,)).astype(float)
        self.inputs["mu"] = self.mu_value.shape
        self.units = s[::d] * V
        if (self.mu == 0).any():  # μ < 0 is no law: audits leave μ alone
            self.audit_inputs = tuple(k for k in self.inputs if k != "mu")
        self.modes, self.options = self._classify(kink_tol)
        self._use_modes(self.modes)
        if self.options:
            self.status = "kink"
            self.kink = Kink(np.array(sorted(self.options)), 0.0)

    def _parts(self, c: int) -> tuple[float, np.ndarray, float, np.ndarray]:
        """(Λ_n, Λ_T, U_n, U_T) of contact c."""
        a = c * self.d
        return self.lam[a], self.lam[a + 1:a + self.d], self.w[a], self.w[a + 1:a + self.d]

    def _classify(self, tol: float) -> tuple[list[int], dict[int, tuple[int, int]]]:
        modes, options = [], {}
        for c, unit in enumerate(self.units):
            ln, lt, un, ut = self._parts(c)
            ln, lt, un, ut = ln / unit, np.linalg.norm(lt) / unit, un / unit, \
                np.linalg.norm(ut) / unit
            closed = SLIDE if ut > tol or self.mu[c] == 0 else STICK
            if ln <= tol:
                modes.append(SEPARATE)
                if un <= tol:
                    options[c] = (SEPARATE, closed)
            elif closed == SLIDE:
                modes.append(SLIDE)
            else:
                modes.append(STICK)
                if self.mu[c] * ln - lt <= tol:
                    options[c] = (STICK, ONSET)
        return modes, options

    def _equations(self, modes: list[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """F_Λ, F_U (m × m) and F_μ (m × contacts) of the modes' equations."""
        FL, FU, Fmu = mode_equations(np.array([modes]), self.lam[None], self.w[None],
                                     self.mu, self.d)
        return FL[0], FU[0], Fmu[0]

    def _use_modes(self, modes: list[int]) -> None:
        FL, FU, Fmu = self._equations(modes)
        J = FL + FU @ self.G
        self.K = np.linalg.solve(J, FU)
        self.Kmu = np.linalg.solve(J, Fmu)
        self.condition = float(np.linalg.cond(J))
        self.impulses_unique = True
        self._J, self._FU = J, FU
        self.__dict__.pop("_measures", None)
        self.__dict__.pop("_point", None)

    @cached_property
    def _measures(self) -> tuple[float, float]:
        R = self.IE @ self.W.T
        FR = self._FU @ R
        scale = np.linalg.norm(FR) or 1.0
        return (float(np.linalg.norm(self._J @ (self.K @ R) - FR) / scale),
                self._radius(self.modes, -(self.K @ R)))

    def _radius(self, modes: list[int], dlam: np.ndarray) -> float:
        """First-order distance, relative to ‖u⁻‖, to the nearest change of mode: each
        mode's positive quantity over the norm of its gradient in u⁻ (exact for separated
        and sticking contacts, on which the map is affine)."""
        dU = self.G @ dlam + self.IE @ self.W.T
        radii = []
        for c, mode in enumerate(modes):
            a, d = c * self.d, self.d
            ln, lt, un, ut = self._parts(c)
            if mode == SEPARATE:
                pairs = [(un, dU[a])]
            elif mode == STICK:
                tl = lt / (np.linalg.norm(lt) or 1.0)
                pairs = [(ln, dlam[a]), (self.mu[c] * ln - np.linalg.norm(lt),
                                         self.mu[c] * dlam[a] - tl @ dlam[a + 1:a + d])]
            else:
                tu = ut / (np.linalg.norm(ut) or 1.0)
                pairs = [(ln, dlam[a])] + ([(np.linalg.norm(ut), tu @ dU[a + 1:a + d])]
                                           if self.mu[c] > 0 else [])
            radii += [v / np.linalg.norm(g) for v, g in pairs if np.linalg.norm(g) > 0]
        unorm = float(np.linalg.norm(self.u))
        return min(radii, default=np.inf) / unorm if unorm > 0 else 0.0

    def values(self) -> dict[str, Any]:
        return {**super().values(), "mu": self.mu_value}

    def _dmu(self, t: dict[str, np.ndarray]) -> np.ndarray:
        dmu = t.get("mu")
        return np.zeros(self.mu.size) if dmu is None else np.broadcast_to(dmu, self.mu.shape)

    def jvp(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        r, du = self._rhs(tangents)
        dlam = -(self.K @ r) - self.Kmu @ self._dmu(tangents)
        return du + self.Y @ dlam, dlam

    def vjp(self, u_bar: np.ndarray, lam_bar: np.ndarray) -> dict[str, np.ndarray]:
        out = super().vjp(u_bar, lam_bar)
        mu_bar = -((lam_bar + u_bar @ self.Y) @ self.Kmu)
        out["mu"] = mu_bar if self.mu_value.ndim else mu_bar.sum(axis=1)
        return out

    def directional(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        if not self.options:
            return self.jvp(tangents)
        for piece in self._assignments(2 ** len(self.options)):
            du, dlam = piece.jvp(tangents)
            if self._consistent(piece.modes, dlam, tangents):
                return du, dlam
        raise NoSolutionError("no mode of the degenerate contacts is consistent along this "
                              "direction (the directional derivative needs more than the "
                              "adjacent modes)")

    def _consistent(self, modes: list[int], dlam: np.ndarray, t: dict) -> bool:
        r, _ = self._rhs(t)
        dU = self.G @ dlam + r
        dmu = self._dmu(t)
        scale = 1e-9 * (np.abs(dU).max(initial=0.0) + np.abs(dlam).max(initial=0.0) *
                        np.abs(self.G).max(initial=0.0)) + 1e-300
        lam_scale = scale / max(np.abs(self.G).max(), 1e-300)
        for c in self.options:
            a, d = c * self.d, self.d
            ln, lt, _, _ = self._parts(c)
            tl = lt / (np.linalg.norm(lt) or 1.0)
            if modes[c] == SEPARATE:
                ok = dU[a] >= -scale
            elif modes[c] == ONSET:  # slides along −t̂, Λ_T's direction: −t̂·dU_T ≥ 0
                ok = -tl @ dU[a + 1:a + d] >= -scale
            elif self.options[c][0] == SEPARATE:  # the contact closes: Λ_n grows
                ok = dlam[a] >= -lam_scale
            else:  # sticking stays inside the cone
                ok = self.mu[c] * dlam[a] + ln * dmu[c] - tl @ dlam[a + 1:a + d] >= -lam_scale
            if not ok:
                return False
        return True

    def _assignments(self, cap: int) -> list[CoulombMap]:
        out = []
        keys = sorted(self.options)
        for combo in itertools.product(*(self.options[c] for c in keys)):
            piece = object.__new__(CoulombMap)
            piece.__dict__.update(self.__dict__)
            modes = list(self.modes)
            for c, mode in zip(keys, combo, strict=True):
                modes[c] = mode
            piece.modes, piece.options, piece.status, piece.kink = modes, {}, "smooth", None
            piece._use_modes(modes)
            out.append(piece)
            if len(out) >= cap:
                break
        return out

    def pieces(self, cap: int) -> list[LocalMap]:
        return list(self._assignments(cap)) if self.options else [self]

    def evaluate(self, data: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        return self._evaluate(data)


def coulomb_map(law: Any, problem: Any, answer: Any, kink_tol: float) -> CoulombMap:
    """The local map of Coulomb's law ``law`` at ``answer`` on ``problem``: differentiable
    in u⁻, M, W, ``"mu"`` and ``"restitution"`` (docs/theory.md §18–§19). Audits evaluate the
    law by :func:`impactqp.solve_friction` on the local problem U = GΛ + q."""
    d, nc = problem.contact_dim, problem.n_contacts

    def evaluate(data: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        M, W, u = data["M"], data["W"], data["u_minus"]
        Y = np.linalg.solve(M, W)
        G = W.T @ Y
        q = W.T @ u
        q[::d] *= 1.0 + np.broadcast_to(data["restitution"], (nc,))
        local = FrictionContactProblem(0.5 * (G + G.T), q,
                                       np.broadcast_to(data["mu"], (nc,)).copy(),
                                       contact_dim=d)
        lam = solve_friction(local, tol=1e-12).r
        return u + Y @ lam, lam

    return CoulombMap(problem.M, problem.W, problem.u_minus, answer.impulses, d=d,
                      mu=law.mu, restitution=normal_rows("restitution", law.restitution, nc, d),
                      kink_tol=kink_tol, evaluate=evaluate)


def mode_equations(modes: np.ndarray, lam: np.ndarray, U: np.ndarray, mu: np.ndarray,
                   d: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """F_Λ, F_U (s, m, m) and F_μ (s, m, contacts) of the modes' equations F(Λ, U, μ) = 0
    (docs/theory.md §18) for s answers at once: ``modes`` (s, contacts), ``lam`` and ``U``
    (s, m), ``mu`` (contacts,), d rows per contact."""
    s, m = lam.shape
    FL, FU, Fmu = np.zeros((s, m, m)), np.zeros((s, m, m)), np.zeros((s, m, m // d))
    eye = np.eye(d - 1)
    for c in range(m // d):
        a, T = c * d, slice(c * d + 1, c * d + d)
        mode = modes[:, c]
        FL[mode == SEPARATE, a:a + d, a:a + d] = np.eye(d)
        FU[mode == STICK, a:a + d, a:a + d] = np.eye(d)
        rows = np.flatnonzero((mode == SLIDE) | (mode == ONSET))
        if rows.size == 0:
            continue
        ln, lt, ut = lam[rows, a], lam[rows, a + 1:a + d], U[rows, a + 1:a + d]
        size = np.linalg.norm(ut, axis=1)
        onset = mode[rows] == ONSET
        grip = np.linalg.norm(lt, axis=1)
        t = np.where(onset[:, None], -lt / np.where(grip > 0, grip, 1.0)[:, None],
                     ut / np.where(size > 0, size, np.inf)[:, None])
        FU[rows, a, a] = 1.0
        FL[rows, T, T] = eye
        FL[rows, T, a] = mu[c] * t
        Fmu[rows, T, c] = ln[:, None] * t
        # sliding that starts at the answer (docs/theory.md §18): the slip leaves along −t̂,
        # so Λ_T's grip along t̂ follows μΛ_n while across t̂ the slip stays 0 (Λ_T's turn
        # there is set by the next order): t̂t̂ᵀdΛ_T − μt̂ dΛ_n + (I − t̂t̂ᵀ)dU_T = 0
        across = eye - np.einsum("si,sj->sij", t[onset], t[onset])
        FL[rows[onset], T, T] = eye - across
        FU[rows[onset], T, T] = across
        bend = ~onset & (size > 0)
        FU[rows[bend], T, T] = (mu[c] * ln[bend] / size[bend])[:, None, None] * (
            eye - np.einsum("si,sj->sij", t[bend], t[bend]))
    return FL, FU, Fmu
