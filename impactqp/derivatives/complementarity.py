"""The derivative of a complementarity law ``0 ≤ Λ ⟂ GΛ + (I + E)Wᵀu⁻ ≥ 0``,
u⁺ = u⁻ + M⁻¹WΛ (Moreau E = εI, local Newton, Frémond; docs/theory.md §3, §18–§19).

On the answer's active set A, Λ_A = −G_AA⁺q_A and every input enters through
q = (I + E)Wᵀu⁻ and G = WᵀM⁻¹W:

    dΛ = −K(dG Λ + dq),  dq = (I + E)(Wᵀdu⁻ + dWᵀu⁻) + dE γ⁻,
    dG Λ = dWᵀv + Yᵀ(dW Λ − dM v),  du⁺ = du⁻ + M⁻¹(dW Λ − dM v) + Y dΛ,

with K = G_AA⁺ embedded, Y = M⁻¹W and v = YΛ = u⁺ − u⁻. For Moreau's law this is
du⁺ = (I − (1 + ε)P_A)du⁻ with P_A = M⁻¹W_A G_AA⁺W_Aᵀ. The VJP is the transpose of the
same few products (docs/theory.md §18), one compiled definition of each
(:mod:`impactqp.kernels.local_map`).

A dense problem's derivative is formed from its structure's operators by one compiled call
(:meth:`ComplementarityMap.at`): the classification, the factor of G_AA and every figure of
the certificate (margin, residual of the solves, condition). A kink or a singular G_AA is
formed here instead (eigen-decompositions: the minimum-norm element, the degenerate set).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np

from ..errors import DerivativeUnsupportedError
from ..kernels import local_map as compiled
from ..kernels.derivative import SMOOTH
from ..qp.lcp import solve_lcp
from . import lcp
from .local import Kink, LocalMap
from .operands import EMPTY, POINT_SIZE, UNPACK, dense, directions, operands

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
    identity : bool
        E = value·I (a scalar value): the compiled cell forms I + E itself.
    """

    name: str
    value: np.ndarray
    to_E: Callable[[np.ndarray], np.ndarray]
    cotangent: Callable[[np.ndarray], np.ndarray]
    identity: bool = False


def scalar_times_identity(name: str, value: float, m: int) -> Parameter:
    """E = value·I (Moreau's ε, one Newton coefficient for every contact)."""
    return Parameter(name, np.asarray(float(value)), lambda p: float(p) * np.eye(m),
                     lambda Ebar: np.trace(Ebar, axis1=1, axis2=2), True)


def diagonal(name: str, value: np.ndarray) -> Parameter:
    """E = diag(value) (local Newton with one coefficient per contact)."""
    return Parameter(name, np.asarray(value, dtype=float).copy(), np.diag,
                     lambda Ebar: np.diagonal(Ebar, axis1=1, axis2=2).copy())


def full_matrix(name: str, value: np.ndarray) -> Parameter:
    """E itself (Frémond's matrix of impact coefficients)."""
    return Parameter(name, np.asarray(value, dtype=float).copy(),
                     lambda p: np.asarray(p, dtype=float), lambda Ebar: Ebar)


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

    @classmethod
    def at(cls, problem: Any, impulses: np.ndarray, parameter: Parameter, *,
           kink_tol: float) -> ComplementarityMap:
        """The local map at the answer ``impulses`` on ``problem``: for a dense problem, its
        cell and certificate figures in one compiled call
        (:func:`impactqp.kernels.local_map.local_cell`) on the structure's operators; a
        kink, a singular G_AA, a sparse problem or one without contacts through the
        constructor."""
        st = problem.structure
        if st.sparse or st.n > DENSE_LIMIT or st.m == 0:
            return cls(problem.M, problem.W, problem.u_minus, impulses, parameter,
                       kink_tol=kink_tol)
        ops = operands(st)
        n, m = ops.W.shape
        u = np.ascontiguousarray(problem.u_minus, dtype=float)
        lam = np.ascontiguousarray(impulses, dtype=float)
        E, eps = (EMPTY[2], float(parameter.value)) if parameter.identity else \
            (np.ascontiguousarray(parameter.to_E(parameter.value), dtype=float), 0.0)
        size = POINT_SIZE(n, m)
        out = np.empty(size + 2 * m + 3)
        if compiled.local_cell(ops.packed, ops.Minv, E, eps, u, lam, float(kink_tol),
                               out) != SMOOTH:
            return cls(ops.M, ops.W, u, lam, parameter, kink_tol=kink_tol)
        self = object.__new__(cls)
        self.M, self.W, self.Minv, self.Y, self.G = ops.M, ops.W, ops.Minv, ops.Y, ops.G
        self.u, self.lam, self.parameter = u, lam, parameter
        self._cell, self._point, self.impulses_unique = out, out[:size], True
        margin, residual, self.condition = out[-3:].tolist()
        self.__dict__["_measures"] = (residual, margin)  # measured by the kernel
        return self

    # What the compiled cell holds, read from it when first needed (the constructor sets
    # them itself).
    @cached_property
    def inputs(self) -> dict[str, tuple[int, ...]]:  # type: ignore[override]
        n, m = self.W.shape
        return {"u_minus": (n,), "M": (n, n), "W": (n, m),
                self.parameter.name: self.parameter.value.shape}

    @cached_property
    def _fields(self) -> compiled.Point:
        return UNPACK(self._cell, *self.W.shape)

    @cached_property
    def K(self) -> np.ndarray:
        return self._fields.K

    @cached_property
    def IE(self) -> np.ndarray:
        return self._fields.IE

    @cached_property
    def v(self) -> np.ndarray:
        return self._fields.v

    @cached_property
    def gamma(self) -> np.ndarray:
        return self._fields.gamma

    @cached_property
    def w(self) -> np.ndarray:
        m = self.W.shape[1]
        return self._cell[-2 * m - 3:-m - 3]

    @cached_property
    def active(self) -> np.ndarray:
        m = self.W.shape[1]
        return self._cell[-m - 3:-3] > 0.5

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
        self.M, self.W = dense(M), dense(W)
        self.u = np.ascontiguousarray(u_minus, dtype=float)
        self.lam, self.parameter = np.ascontiguousarray(impulses, dtype=float), parameter
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
        self.v = self.Y @ self.lam
        self.w = self.G @ self.lam + self.q
        s = np.sqrt(np.maximum(np.diag(self.G), 1e-300))
        return s, float(np.sqrt(max(self.u @ self.M @ self.u, 0.0))) or 1.0

    @cached_property
    def q(self) -> np.ndarray:
        """q = (I + E)γ⁻, the LCP's vector."""
        return self.IE @ self.gamma

    @cached_property
    def aset(self) -> lcp.ActiveSet:
        """The classification (the compiled path's cell has no degenerate contact)."""
        return lcp.ActiveSet(self.active, np.zeros_like(self.active), np.nan)

    @cached_property
    def _point(self) -> np.ndarray:
        """The compiled kernels' operands at this answer, with this piece's K, packed
        (:class:`~impactqp.kernels.local_map.Point`; the compiled cell comes with its own)."""
        return compiled.pack_point(self.Minv, self.Y, self.W, self.IE, self.K, self.u,
                                   self.lam, self.v, self.gamma)

    def _directions(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, ...]:
        return directions(tangents, self.parameter.name, self.parameter.to_E)

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
        self.__dict__.pop("_point", None)

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
        return compiled.rhs(self._point, *self.W.shape, *self._directions(t))

    def jvp(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        return compiled.jvp(self._point, *self.W.shape, *self._directions(tangents))

    def directional(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        r, du = self._rhs(tangents)
        dlam = lcp.directional(self.G, self.lam, self.aset, dq=r)
        return du + self.Y @ dlam, dlam

    def vjp(self, u_bar: np.ndarray, lam_bar: np.ndarray) -> dict[str, np.ndarray]:
        k, (n, m) = u_bar.shape[0], self.W.shape
        identity = self.parameter.identity  # its cotangent is tr Ē: Ē is not formed
        out = compiled.Cotangents(np.empty((k, n)), np.empty((k, n, n)), np.empty((k, n, m)),
                                  np.empty((k, 0, 0) if identity else (k, m, m)))
        trace = np.empty(k)
        compiled.vjp(self._point, np.ascontiguousarray(u_bar, dtype=float),
                     np.ascontiguousarray(lam_bar, dtype=float), *out, trace)
        return {"u_minus": out.u, "M": out.M, "W": out.W,
                self.parameter.name: trace if identity else self.parameter.cotangent(out.E)}

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
