"""Backend-neutral convex programs that impact laws emit and backends solve.

Every law of impactqp reduces to one quadratic program

    minimize    ½ xᵀ P x + cᵀ x
    subject to  A x ≥ b

with P symmetric positive semidefinite. Two shapes occur (docs/theory.md §3, §9):

* velocity form:  x = v, P = M, c = −M u⁻, A = Wᵀ, b = 0 (the multipliers are the impulses);
* impulse form:   x = Λ, P = G, c = q,      A = I,  b = 0 (an LCP with a symmetric matrix).

A velocity program of a 1-D chain says so (:class:`ChainShape`), so that the isotonic
backend can solve it in O(N) (docs/theory.md §5); built as a :class:`ChainProgram`, its
matrices are formed only when a backend other than that one asks for them.

Backends only see a :class:`QuadraticProgram`; they never know which law produced it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np
import scipy.sparse as sp


@dataclass(frozen=True)
class ChainShape:
    """The structure of a chain's velocity program: P = diag(weights), the rows of A are the
    gaps v₂−v₁ … v_N−v_{N−1}, preceded by v₁ (a left wall) and followed by −v_N (a right
    wall) when present, and b = 0 (docs/theory.md §5)."""

    weights: np.ndarray
    left_wall: bool = False
    right_wall: bool = False
    center: np.ndarray | None = field(default=None, compare=False)
    """The point the program projects, when known exactly (c = −diag(weights)·center):
    the isotonic backend regresses it as it is instead of dividing c by the weights."""

    @property
    def n_constraints(self) -> int:
        """Number of rows of A: the gaps and the walls."""
        return self.weights.size - 1 + self.left_wall + self.right_wall


@dataclass(frozen=True)
class QuadraticProgram:
    """min ½xᵀPx + cᵀx  s.t.  Ax ≥ b.

    Attributes
    ----------
    P : (k, k) ndarray or sparse
        Symmetric positive semidefinite.
    c : (k,) ndarray
    A : (r, k) ndarray or sparse, or None for the non-negativity constraint x ≥ 0
        (A = I, b = 0: the impulse form of an LCP).
    b : (r,) ndarray or None
    factor : (p, k) ndarray, optional
        A matrix B with P = BᵀB, when known; lets the NNLS path work without refactorizing.
    factor_rhs : (p,) ndarray, optional
        d with c = Bᵀd, when known (Moreau's law: d = (1+ε)Lᵀu⁻).
    cache_owner, cache_tag : optional
        Programs with the same owner (an object that outlives them, e.g. the problem
        structure) and tag share P, A and b and differ only in c; backends that compile
        (cvxpy) keep one compiled problem per (owner, tag) and re-solve it.
    chain : ChainShape, optional
        Set on velocity programs of 1-D chains.
    """

    P: Any
    c: np.ndarray
    A: Any = None
    b: np.ndarray | None = None
    factor: np.ndarray | None = None
    factor_rhs: np.ndarray | None = None
    cache_owner: Any = field(default=None, compare=False)
    cache_tag: str = ""
    chain: ChainShape | None = field(default=None, compare=False)

    @property
    def n_vars(self) -> int:
        return int(self.c.size)

    @property
    def nonnegative(self) -> bool:
        """True for the impulse (LCP) shape x ≥ 0."""
        return self.A is None

    @property
    def sparse(self) -> bool:
        return sp.issparse(self.P) or sp.issparse(self.A)

    @property
    def n_constraints(self) -> int:
        return self.n_vars if self.A is None else int(self.A.shape[0])

    def constraint_matrix(self) -> Any:
        """A (the identity for the non-negative shape), dense or sparse like P."""
        if self.A is not None:
            return self.A
        return sp.identity(self.n_vars, format="csc") if self.sparse else np.eye(self.n_vars)

    def constraint_rhs(self) -> np.ndarray:
        return np.zeros(self.n_constraints) if self.b is None else self.b

    def slack(self, x: np.ndarray) -> np.ndarray:
        """A x − b (≥ 0 when x is feasible)."""
        if self.A is None:
            return x.copy()
        return np.asarray(self.A @ x).ravel() - self.constraint_rhs()

    def gradient(self, x: np.ndarray) -> np.ndarray:
        return np.asarray(self.P @ x).ravel() + self.c

    def kkt_residuals(self, x: np.ndarray, y: np.ndarray) -> dict[str, float]:
        """Absolute KKT residuals of a primal-dual pair (stationarity Px + c = Aᵀy)."""
        grad = self.gradient(x)
        stat = grad - (y if self.A is None else np.asarray(self.A.T @ y).ravel())
        s = self.slack(x)
        return {
            "stationarity": float(np.max(np.abs(stat), initial=0.0)),
            "primal": float(max(0.0, -np.min(s, initial=0.0))),
            "dual": float(max(0.0, -np.min(y, initial=0.0))),
            "complementarity": float(np.max(np.abs(s * y), initial=0.0)),
        }


@dataclass
class QPSolution:
    """What a backend returns: primal x, multipliers y ≥ 0 of Ax ≥ b, and its own status."""

    x: np.ndarray
    y: np.ndarray
    status: str
    backend: str
    iterations: int | None = None
    info: dict = field(default_factory=dict)


class ChainProgram(QuadraticProgram):
    """The velocity program of a 1-D chain (docs/theory.md §5) with P, A and c formed on first
    access: the isotonic backend reads only :attr:`chain`, so an O(N) solve never forms a
    matrix; any other backend gets P and A from ``matrices`` when it asks for them.

    Parameters
    ----------
    shape : ChainShape
        Weights (P = diag(weights)), walls and ``center`` (required: c = −P·center).
    matrices : callable
        Returns (P, A) when first needed (the owner's cached matrices).
    sparse : bool
        What :attr:`sparse` reports (the owner's storage), without forming P.
    cache_owner, cache_tag
        As for :class:`QuadraticProgram`.
    """

    def __init__(self, shape: ChainShape, matrices: Callable[[], tuple[Any, Any]], *,
                 sparse: bool, cache_owner: Any = None, cache_tag: str = "") -> None:
        if shape.center is None:
            raise ValueError("a ChainProgram needs the chain's center (c = −P·center)")
        for name, value in (("factor", None), ("factor_rhs", None),
                            ("cache_owner", cache_owner), ("cache_tag", cache_tag),
                            ("chain", shape), ("_matrices", matrices), ("_sparse", sparse)):
            object.__setattr__(self, name, value)

    @cached_property
    def _formed(self) -> tuple[Any, Any]:
        return self._matrices()

    P = property(lambda self: self._formed[0], doc="diag(weights), formed on first access.")
    A = property(lambda self: self._formed[1], doc="The gap (and wall) rows, formed on first "
                                                   "access.")

    @cached_property
    def c(self) -> np.ndarray:
        """−diag(weights)·center."""
        return -(self.chain.weights * self.chain.center)

    @cached_property
    def b(self) -> np.ndarray:
        """Zeros: the rows are Av ≥ 0."""
        return np.zeros(self.chain.n_constraints)

    n_vars = property(lambda self: int(self.chain.weights.size))
    n_constraints = property(lambda self: self.chain.n_constraints)
    nonnegative = property(lambda self: False)
    sparse = property(lambda self: self._sparse)
