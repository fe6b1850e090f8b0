"""What a law says about its impact map near one answer: a :class:`LocalMap`
(docs/theory.md §18–§19).

A law that knows its derivative returns a local map from its ``derivative`` method: the
inputs it depends on (u⁻, and M, W and its own parameter where it can), the default element
of its (generalized) Jacobian as a JVP and a VJP, the one-sided derivative along a
direction, the limiting pieces at a kink, and how far the answer is from the nearest change
of piece. :class:`~impactqp.derivatives.impact.ImpactDerivative` turns it into Jacobians
and a certificate. A user's law may return a :class:`LinearPiece`, a map that is linear
near its answer.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, NamedTuple

import numpy as np

from ..errors import ShapeError


class Kink(NamedTuple):
    """Where an answer sits on a kink of its law's map (docs/theory.md §19).

    Attributes
    ----------
    contacts : ndarray of int
        The degenerate contacts (λᵢ = 0 = wᵢ; for the sector law, the entries of u⁻ tied
        with a neighbour).
    distance : float
        How far the answer is from exactly degenerate, in the dimensionless units of the
        classification (at most the ``kink_tol`` that flagged it).
    """

    contacts: np.ndarray
    distance: float


class LocalMap(ABC):
    """The impact map (u⁻, M, W, parameter) ↦ (u⁺, Λ) near one answer.

    Attributes
    ----------
    inputs : dict of str to tuple
        The inputs the map is differentiable in, with their shapes.
    status : str
        ``"smooth"`` (a stable piece) or ``"kink"``.
    margin : float
        Distance, relative to ‖u⁻‖, from u⁻ to the nearest u⁻ where the piece changes
        (0 at a kink, +inf if none).
    kink : Kink or None
    residual : float
        Relative residual of the linear solves behind the derivative.
    condition : float
        Condition estimate of those solves.
    impulses_unique : bool
        Λ is locally unique; when not, the impulse derivatives are the minimum-norm ones.
    reach : float
        Like ``margin`` but over the non-degenerate pieces only: at a kink, how far the
        one-sided derivatives hold along a ray (audits step within it).
    """

    inputs: dict[str, tuple[int, ...]]
    status: str = "smooth"
    margin: float = np.inf
    kink: Kink | None = None
    residual: float = 0.0
    condition: float = 1.0
    impulses_unique: bool = True
    reach: float = np.inf
    audit_inputs: tuple[str, ...] | None = None
    """The inputs an audit perturbs (None: all); a parameter at the edge of its domain
    (Coulomb's μ = 0) is left alone."""

    @abstractmethod
    def values(self) -> dict[str, Any]:
        """The current inputs (the point the map is differentiated at)."""

    @abstractmethod
    def jvp(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """(du⁺, dΛ) of the default element along ``tangents`` (missing inputs held)."""

    @abstractmethod
    def vjp(self, u_bar: np.ndarray, lam_bar: np.ndarray) -> dict[str, np.ndarray]:
        """Cotangents of every input for rows of cotangents ``u_bar`` (k, n) and
        ``lam_bar`` (k, m): each (k, ``*shape``)."""

    def directional(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """The one-sided derivative along ``tangents`` (the JVP where smooth)."""
        return self.jvp(tangents)

    def pieces(self, cap: int) -> list[LocalMap]:
        """The limiting pieces at a kink, at most ``cap`` (the map itself where smooth)."""
        return [self]

    def evaluate(self, data: dict[str, Any]) -> tuple[np.ndarray, np.ndarray] | None:
        """(u⁺, Λ) at other inputs, for audits; None to let the caller re-solve the law."""
        return None


class LinearPiece(LocalMap):
    """A map that is linear near its answer, given by its Jacobians: what a user's law may
    return from its ``derivative`` hook.

    Parameters
    ----------
    u_plus : dict of str to ndarray
        ∂u⁺/∂input for each input, shape (n, ``*shape``) for an input of shape ``shape``;
        ``"u_minus"`` at least.
    impulses : dict of str to ndarray, optional
        ∂Λ/∂input likewise, shape (m, ``*shape``); where not given, recovered from the
        momentum equation M du⁺ = M du⁻ + W dΛ (:meth:`with_problem`).
    values : dict of str to array_like
        The inputs' current values (their shapes define ``inputs``).
    margin : float
        Distance, relative to ‖u⁻‖, within which the piece holds (+inf by default).
    """

    def __init__(self, u_plus: dict[str, Any], values: dict[str, Any],
                 impulses: dict[str, Any] | None = None, *, margin: float = np.inf) -> None:
        if "u_minus" not in u_plus:
            raise ShapeError("a LinearPiece needs ∂u⁺/∂u⁻ under 'u_minus'")
        self._values = {k: np.asarray(v, dtype=float) for k, v in values.items()}
        self.inputs = {k: v.shape for k, v in self._values.items()}
        n = self.inputs["u_minus"][0]
        self._ju = {k: np.asarray(v, dtype=float) for k, v in u_plus.items()}
        self._jl = {k: np.asarray(v, dtype=float) for k, v in (impulses or {}).items()}
        self._m = next(iter(self._jl.values())).shape[0] if self._jl else 0
        for name, J in self._ju.items():
            if name not in self.inputs or J.shape != (n, *self.inputs[name]):
                raise ShapeError(f"∂u⁺/∂{name} must have shape ({n}, "
                                 f"{', '.join(map(str, self.inputs.get(name, ('?',))))})")
        self.margin = float(margin)

    def with_problem(self, M: np.ndarray, W: np.ndarray) -> LinearPiece:
        """Itself, with the impulse derivatives not given recovered from the momentum
        equation M du⁺ = M du⁻ + W dΛ (the minimum-norm dΛ; unique when W has full
        column rank)."""
        self._m = W.shape[1]
        pinv = np.linalg.pinv(W)
        self.impulses_unique = bool(np.linalg.matrix_rank(W) == W.shape[1])
        for name, J in self._ju.items():
            if name not in self._jl:
                jump = J.reshape(J.shape[0], -1).copy()
                if name == "u_minus":
                    jump -= np.eye(J.shape[0])
                self._jl[name] = (pinv @ M @ jump).reshape(self._m, *self.inputs[name])
        return self

    def values(self) -> dict[str, Any]:
        return dict(self._values)

    def _apply(self, table: dict, size: int, tangents: dict) -> np.ndarray:
        out = np.zeros(size)
        for name, t in tangents.items():
            if name in table:
                J = table[name]
                out += J.reshape(size, -1) @ np.asarray(t, dtype=float).ravel()
        return out

    def jvp(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        n = self.inputs["u_minus"][0]
        return self._apply(self._ju, n, tangents), self._apply(self._jl, self._m, tangents)

    def vjp(self, u_bar: np.ndarray, lam_bar: np.ndarray) -> dict[str, np.ndarray]:
        out = {}
        for name, shape in self.inputs.items():
            total = np.zeros((u_bar.shape[0], int(np.prod(shape, dtype=int))))
            if name in self._ju:
                total += u_bar @ self._ju[name].reshape(u_bar.shape[1], -1)
            if name in self._jl and lam_bar.shape[1]:
                total += lam_bar @ self._jl[name].reshape(lam_bar.shape[1], -1)
            out[name] = total.reshape(u_bar.shape[0], *shape)
        return out
