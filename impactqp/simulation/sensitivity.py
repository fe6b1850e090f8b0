"""Derivatives of a simulated motion with respect to its initial state and its impact law's
parameter (docs/theory.md §21): what the user asks for, the tangents at every record, the
adjoint, and the kinks where a derivative holds on one side only.

Two derivatives through time exist and a run says which one it holds
(``Sensitivities.kind``): ``"discrete-map"`` for Moreau–Jean time-stepping, the exact
derivative of the map that takes the initial data to the computed states (impact times are
quantized to steps, so ∂q(T)/∂q₀ of a bouncing ball is 1), and ``"flow"`` for event-driven
integration, the derivative of the motion itself (impact times move with the data; the
saltation matrix carries the tangent across each impact; 1.40797… for the same ball).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, NamedTuple

import numpy as np

from ..errors import InputError, ShapeError
from ..laws.base import ImpactLaw

KINDS = ("discrete-map", "flow")
"""The two derivatives through time."""


class TrajectoryKink(NamedTuple):
    """A point of a run where the returned derivative is one element of a set of one-sided
    ones (docs/theory.md §21).

    Attributes
    ----------
    time : float
    kind : str
        ``"activation"`` (a contact on the Moreau–Jean threshold g + ½hγ = 0, where the
        discrete map jumps), ``"degenerate"`` (Λᵢ = 0 = wᵢ in a step's or an impact's LCP),
        ``"grazing"`` (an impact or a touch with ∇g·f⁻ ≈ 0), ``"zeno"`` (an accumulation
        of impacts settled into contact) or ``"simultaneous"`` (contacts closing at one
        event).
    contacts : tuple of int
    distance : float
        How far the run is from the kink, relative to the run's scale: abs(g + ½hγ) over its
        length scale (activation), ∇g·f⁻ or the least gap over its velocity or length
        scale (grazing); 0 where the run sits on the kink (degenerate, Zeno, simultaneous).
    """

    time: float
    kind: str
    contacts: tuple[int, ...]
    distance: float


def full_restitution(law: ImpactLaw, m: int) -> np.ndarray:
    """The (m, m) matrix E of the law's step form ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻`` on every contact."""
    E = law.step_restitution(np.arange(m))
    if E is None:
        raise InputError(f"sensitivities need a law with a complementarity form (Moreau, "
                         f"Newton, Frémond); {law.name!r} has none")
    E = np.asarray(E, dtype=float)
    return E * np.eye(m) if E.ndim == 0 else (np.diag(E) if E.ndim == 1 else E)


def parameter_directions(law: ImpactLaw, m: int) -> np.ndarray:
    """∂E/∂pⱼ for the law's coefficients p (its ``coefficient_key``), as (p, m, m): one
    coefficient for all contacts (ε, a scalar e), one per contact (a vector e) or Frémond's
    m × m matrix, row-major."""
    c = np.asarray(law.coefficients, dtype=float)
    if c.size == 1:
        return np.eye(m)[None]
    if c.ndim == 1:
        out = np.zeros((m, m, m))
        out[np.arange(m), np.arange(m), np.arange(m)] = 1.0
        return out
    return np.eye(m * m).reshape(m * m, m, m)


class Columns(NamedTuple):
    """The tangent columns of each name the user asked for."""

    names: tuple[str, ...]
    slices: dict[str, slice]
    shapes: dict[str, tuple[int, ...]]
    S0: np.ndarray
    pcols: np.ndarray
    directions: np.ndarray


def columns(wrt: Sequence[str], law: ImpactLaw, n: int, m: int) -> Columns:
    """Parse ``sensitivities=`` into tangent columns: ``"q0"`` and ``"v0"`` n each, the
    law's parameter one per coefficient.

    Raises
    ------
    InputError
        An unknown or repeated name, or none.
    """
    if isinstance(wrt, str) or not all(isinstance(w, str) for w in wrt):
        raise InputError(f"sensitivities must be a sequence of names like ('q0', 'v0'), got "
                         f"{wrt!r}")
    key = law.coefficient_key
    known = ("q0", "v0") + ((key,) if key and law.step_restitution(np.arange(m)) is not None
                            else ())
    bad = [w for w in wrt if w not in known]
    if bad or not wrt or len(set(wrt)) != len(wrt):
        raise InputError(f"sensitivities takes distinct names among {known} for {law.name!r}, "
                         f"got {tuple(wrt)!r}")
    directions = parameter_directions(law, m) if key in wrt else np.zeros((0, m, m))
    slices, shapes, start = {}, {}, 0
    for w in wrt:
        size = n if w in ("q0", "v0") else directions.shape[0]
        slices[w], start = slice(start, start + size), start + size
        shapes[w] = (n,) if w in ("q0", "v0") else np.shape(law.coefficients) \
            if np.size(law.coefficients) > 1 else ()
    S0 = np.zeros((2 * n, start))
    for w, rows in (("q0", slice(0, n)), ("v0", slice(n, 2 * n))):
        if w in slices:
            S0[rows, slices[w]] = np.eye(n)
    pcols = np.arange(start)[slices[key]] if key in slices else np.zeros(0, dtype=np.int64)
    return Columns(tuple(wrt), slices, shapes, S0, pcols.astype(np.int64), directions)


class Sensitivities:
    """The tangents of a run at every record, its adjoint and its kinks.

    Parameters
    ----------
    kind : {"discrete-map", "flow"}
    cols : Columns
    tangents : (R, 2n, k) ndarray
        ∂(q, v)/∂(the asked names) at each record.
    adjoint : callable
        ``adjoint(cotangents (R, 2n)) -> (∂L/∂x₀ (2n,), ∂L/∂p (p,))``, the transposed chain.
    kinks : list of TrajectoryKink, or a callable that builds it (called on first read)
    margin : float
        The smallest relative distance to a kink over the run (that of
        :class:`TrajectoryKink`, and the LCPs' margins over each step's speed; +inf when
        nothing came near one).
    """

    def __init__(self, kind: str, cols: Columns, tangents: np.ndarray,
                 adjoint: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]],
                 kinks: list[TrajectoryKink] | Callable[[], list[TrajectoryKink]],
                 margin: float) -> None:
        if kind not in KINDS:
            raise InputError(f"kind must be one of {KINDS}, got {kind!r}")
        self.kind, self.cols, self.tangents = kind, cols, tangents
        self._adjoint, self._kinks, self.margin = adjoint, kinks, margin

    @property
    def kinks(self) -> list[TrajectoryKink]:
        """Where the derivative is one-sided, in the order found."""
        if callable(self._kinks):
            self._kinks = self._kinks()
        return self._kinks

    def of(self, wrt: str | None = None) -> np.ndarray:
        """(R, 2n, k): the tangents with respect to ``wrt`` (every asked name, in order,
        when None); rows [:n] are ∂q, [n:] ∂v."""
        if wrt is None:
            return self.tangents
        if wrt not in self.cols.slices:
            raise InputError(f"no sensitivity with respect to {wrt!r}; the run has "
                             f"{self.cols.names}")
        return self.tangents[:, :, self.cols.slices[wrt]]

    def vjp(self, q: Any = None, v: Any = None) -> dict[str, Any]:
        """Cotangents of every asked name for the loss cotangents ∂L/∂q and ∂L/∂v: each an
        (n,) array (a loss on the final state) or an (R, n) array (one row per record, a loss
        on samples), by the transposed chain (docs/theory.md §21).

        Returns
        -------
        dict
            name → an array shaped like the name (a float for one coefficient).
        """
        R, two_n, _ = self.tangents.shape
        n = two_n // 2
        cot = np.zeros((R, two_n))
        for part, rows in ((q, slice(0, n)), (v, slice(n, two_n))):
            if part is None:
                continue
            a = np.asarray(part, dtype=float)
            if a.shape == (n,):
                cot[-1, rows] = a
            elif a.shape == (R, n):
                cot[:, rows] = a
            else:
                raise ShapeError(f"a cotangent must have shape ({n},) or ({R}, {n}), "
                                 f"got {a.shape}")
        if not np.isfinite(cot).all():
            raise InputError("the cotangents must be finite")
        ax0, ap = self._adjoint(cot)
        out: dict[str, Any] = {}
        for name in self.cols.names:
            if name == "q0":
                out[name] = ax0[:n].copy()
            elif name == "v0":
                out[name] = ax0[n:].copy()
            else:
                shape = self.cols.shapes[name]
                out[name] = float(ap[0]) if shape == () else ap.reshape(shape)
        return out
