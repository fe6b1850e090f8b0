"""The derivative of a complementarity law ``0 ≤ Λ ⟂ GΛ + (I + E)Wᵀu⁻ ≥ 0``,
u⁺ = u⁻ + M⁻¹WΛ (Moreau E = εI, local Newton, Frémond; docs/theory.md §3, §18–§19).

On the answer's active set A, Λ_A = −G_AA⁺q_A and every input enters through
q = (I + E)Wᵀu⁻ and G = WᵀM⁻¹W:

    dΛ = −K(dG Λ + dq),  dq = (I + E)(Wᵀdu⁻ + dWᵀu⁻) + dE γ⁻,
    dG Λ = dWᵀv + Yᵀ(dW Λ − dM v),  du⁺ = du⁻ + M⁻¹(dW Λ − dM v) + Y dΛ,

with K = G_AA⁺ embedded, Y = M⁻¹W and v = YΛ = u⁺ − u⁻. For Moreau's law this is
du⁺ = (I − (1 + ε)P_A)du⁻ with P_A = M⁻¹W_A G_AA⁺W_Aᵀ. The VJP is the transpose of the
same few products (docs/theory.md §18).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np

from ..errors import DerivativeUnsupportedError
from ..qp.lcp import solve_lcp
from . import lcp
from .local import Kink, LocalMap

DENSE_LIMIT = 2000
"""Most degrees of freedom of a derivative: its operands (M⁻¹, the Jacobians) are dense."""


class Parameter(NamedTuple):
    """A law's own differentiable parameter, on which E depends linearly.

    Attributes
    ----------
    name : str
        ``"eps"``, ``"e"``, ``"E"``.
    value : ndarray
        Its current value.
    to_E : callable
        value ↦ E, an (m, m) matrix (linear: the same map takes a tangent to dE).
    cotangent : callable
        Ē of shape (k, m, m) ↦ the parameter's cotangents, shape (k, *value.shape).
    """

    name: str
    value: np.ndarray
    to_E: Callable[[np.ndarray], np.ndarray]
    cotangent: Callable[[np.ndarray], np.ndarray]


def scalar_times_identity(name: str, value: float, m: int) -> Parameter:
    """E = value·I (Moreau's ε, one Newton coefficient for every contact)."""
    return Parameter(name, np.asarray(float(value)), lambda p: float(p) * np.eye(m),
                     lambda Ebar: np.trace(Ebar, axis1=1, axis2=2))


def diagonal(name: str, value: np.ndarray) -> Parameter:
    """E = diag(value) (local Newton with one coefficient per contact)."""
    return Parameter(name, np.asarray(value, dtype=float).copy(), np.diag,
                     lambda Ebar: np.diagonal(Ebar, axis1=1, axis2=2).copy())


def full_matrix(name: str, value: np.ndarray) -> Parameter:
    """E itself (Frémond's matrix of impact coefficients)."""
    return Parameter(name, np.asarray(value, dtype=float).copy(),
                     lambda p: np.asarray(p, dtype=float), lambda Ebar: Ebar)


def _dense(A: Any) -> np.ndarray:
    return np.asarray(A.toarray() if hasattr(A, "toarray") else A, dtype=float)


class ComplementarityMap(LocalMap):
    """The local map of a complementarity law at one answer (docs/theory.md §18–§19).

    Parameters
    ----------
    M, W : array_like or sparse
        The problem's mass matrix and force directions.
    u_minus, impulses : (n,), (m,) ndarray
        The point: u⁻ and the law's impulses Λ there.
    parameter : Parameter
    kink_tol : float
        Contacts with both Λᵢ√Gᵢᵢ and wᵢ/√Gᵢᵢ at most kink_tol·‖u⁻‖_M are degenerate.
    """

    def __init__(self, M: Any, W: Any, u_minus: np.ndarray, impulses: np.ndarray,
                 parameter: Parameter, *, kink_tol: float) -> None:
        s, V = self._setup(M, W, u_minus, impulses, parameter)
        w = self.w
        self.aset = self._absorb_redundant(lcp.classify(impulses * s / V, w / (s * V),
                                                        kink_tol), s * V, kink_tol)
        self._use(self.aset.active)
        D = np.flatnonzero(self.aset.degenerate)
        if D.size:
            self.status = "kink"
            self.kink = Kink(D, float(max(np.abs(impulses[D] * s[D] / V).max(),
                                          np.abs(w[D] / (s[D] * V)).max())))

    @property
    def margin(self) -> float:  # type: ignore[override]
        return 0.0 if self.status == "kink" else self._measures[1]

    @property
    def reach(self) -> float:  # type: ignore[override]
        """The radius over the non-degenerate contacts (the margin off a kink)."""
        return self._measures[1]

    @property
    def residual(self) -> float:  # type: ignore[override]
        return self._measures[0]

    def _setup(self, M: Any, W: Any, u_minus: np.ndarray, impulses: np.ndarray,
               parameter: Parameter) -> tuple[np.ndarray, float]:
        """The operands every derivative reuses; returns the classification's units
        (sᵢ = √Gᵢᵢ, V = ‖u⁻‖_M)."""
        if M.shape[0] > DENSE_LIMIT:
            raise DerivativeUnsupportedError(
                f"the derivative of an impact with n = {M.shape[0]} degrees of freedom: "
                f"derivatives are formed densely, up to n = {DENSE_LIMIT}")
        self.M, self.W = _dense(M), _dense(W)
        self.u, self.lam, self.parameter = np.asarray(u_minus, float), impulses, parameter
        n, m = self.W.shape
        self.inputs = {"u_minus": (n,), "M": (n, n), "W": (n, m),
                       parameter.name: parameter.value.shape}
        self.Minv = np.linalg.inv(self.M)
        self.Minv = 0.5 * (self.Minv + self.Minv.T)
        self.Y = self.Minv @ self.W
        G = self.W.T @ self.Y
        self.G = 0.5 * (G + G.T)
        self.gamma = self.W.T @ self.u
        self.IE = np.eye(m) + parameter.to_E(parameter.value)
        self.v = self.Y @ impulses
        self.q = self.IE @ self.gamma
        self.w = self.G @ impulses + self.q
        s = np.sqrt(np.maximum(np.diag(self.G), 1e-300))
        return s, float(np.sqrt(max(self.u @ self.M @ self.u, 0.0))) or 1.0

    def _absorb_redundant(self, aset: lcp.ActiveSet, scale: np.ndarray,
                          kink_tol: float) -> lcp.ActiveSet:
        """A degenerate contact whose column of W is a combination of the active ones (a
        redundant contact) is no kink of u⁺ when the minimum-norm impulses of A ∪ D are
        positive: the answer is then inside the cell of A ∪ D, with non-unique Λ
        (docs/theory.md §18)."""
        if not aset.degenerate.any():
            return aset
        both = aset.active | aset.degenerate
        if lcp.factor(self.G, both).rank != lcp.factor(self.G, aset.active).rank:
            return aset
        lam = -(lcp.factor(self.G, both).K @ self.q)
        if not np.all(lam[both] * scale[both] > kink_tol):
            return aset
        return lcp.ActiveSet(both, np.zeros_like(both), aset.margin)

    def _use(self, active: np.ndarray) -> None:
        """Factor G on ``active`` (the cell's measures follow when first read)."""
        self.active = active
        f = lcp.factor(self.G, active)
        self.K = f.K
        self.condition = f.condition
        self.impulses_unique = f.rank == int(active.sum())
        self.__dict__.pop("_measures", None)

    @cached_property
    def _measures(self) -> tuple[float, float]:
        """(residual of the solves, radius of the cell relative to ‖u⁻‖), measured when
        first read: a JVP or VJP does not pay for them (docs/theory.md §20)."""
        active = self.active
        R = self.IE @ self.W.T  # ∂q/∂u⁻
        A = np.flatnonzero(active)
        X = self.K[np.ix_(A, A)] @ R[A]
        scale = np.linalg.norm(R[A]) or 1.0
        residual = float(np.linalg.norm(self.G[np.ix_(A, A)] @ X - R[A]) / scale)
        dlam = -self.K @ R  # ∂Λ/∂u⁻ on this cell, and ∂w/∂u⁻ = G ∂Λ/∂u⁻ + R
        dw = self.G @ dlam + R
        # Λ_A = −G_AA⁺q_A, the minimum-norm impulses (the solver's where unique): where Λ is
        # not unique, the radius of the cell in which they stay ≥ 0 is a lower bound
        values = np.where(active, -(self.K @ self.q), self.w)
        grads = np.linalg.norm(np.where(active[:, None], dlam, dw), axis=1)
        keep = ~self.aset.degenerate & (grads > 0)
        unorm = float(np.linalg.norm(self.u))
        radii = values[keep] / grads[keep]
        return residual, (float(radii.min()) / unorm if radii.size and unorm > 0 else
                          (np.inf if not radii.size else 0.0))

    def values(self) -> dict[str, Any]:
        return {"u_minus": self.u, "M": self.M, "W": self.W,
                self.parameter.name: self.parameter.value}

    def _rhs(self, t: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """(r = dG Λ + dq, the part of du⁺ outside Y dΛ) for tangents ``t``."""
        n, m = self.W.shape
        r, du = np.zeros(m), np.zeros(n)
        if (d := t.get("u_minus")) is not None:
            r += self.IE @ (self.W.T @ d)
            du += d
        if (d := t.get(self.parameter.name)) is not None:
            r += self.parameter.to_E(d) @ self.gamma
        if (d := t.get("W")) is not None:
            dW_lam = d @ self.lam
            r += self.IE @ (d.T @ self.u) + d.T @ self.v + self.Y.T @ dW_lam
            du += self.Minv @ dW_lam
        if (d := t.get("M")) is not None:
            dMv = d @ self.v
            r -= self.Y.T @ dMv
            du -= self.Minv @ dMv
        return r, du

    def jvp(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        r, du = self._rhs(tangents)
        dlam = -(self.K @ r)
        return du + self.Y @ dlam, dlam

    def directional(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        r, du = self._rhs(tangents)
        dlam = lcp.directional(self.G, self.lam, self.aset, dq=r)
        return du + self.Y @ dlam, dlam

    def vjp(self, u_bar: np.ndarray, lam_bar: np.ndarray) -> dict[str, np.ndarray]:
        lt = lam_bar + u_bar @ self.Y
        rb = -(lt @ self.K)
        a = u_bar @ self.Minv + rb @ self.Y.T
        rho = rb @ self.IE
        Wbar = a[:, :, None] * self.lam[None, None, :] + self.v[None, :, None] * rb[:, None, :] \
            + self.u[None, :, None] * rho[:, None, :]
        return {"u_minus": u_bar + rho @ self.W.T, "M": -a[:, :, None] * self.v[None, None, :],
                "W": Wbar,
                self.parameter.name: self.parameter.cotangent(
                    rb[:, :, None] * self.gamma[None, None, :])}

    def pieces(self, cap: int) -> list[LocalMap]:
        out: list[LocalMap] = []
        for mask in lcp.limiting_active_sets(self.aset, cap):
            piece = object.__new__(ComplementarityMap)
            piece.__dict__.update(self.__dict__)
            piece.aset = lcp.ActiveSet(mask, np.zeros_like(mask), 0.0)
            piece._use(mask)
            piece.status, piece.kink = "smooth", None
            out.append(piece)
        return out

    def evaluate(self, data: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        """(u⁺, Λ) of the same law at other inputs, through the library's LCP solver."""
        M, W, u = data["M"], data["W"], data["u_minus"]
        Y = np.linalg.solve(M, W)
        G = W.T @ Y
        E = self.parameter.to_E(data[self.parameter.name])
        q = (np.eye(W.shape[1]) + E) @ (W.T @ u)
        lam = solve_lcp(0.5 * (G + G.T), q, tol=1e-12).z
        return u + Y @ lam, lam
