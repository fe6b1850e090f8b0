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
        of impacts settled into contact), ``"simultaneous"`` (contacts closing at one
        event), ``"stick-slide"`` (a frictional contact of a step on the edge of its
        cone: ‖Λ_T‖ = μΛ_n with U_T = 0) or ``"indeterminate"`` (a frictional step whose
        impulses, and velocities, the law does not fix: redundant contacts sliding).
    contacts : tuple of int
    distance : float
        How far the run is from the kink, relative to the run's scale: abs(g + ½hγ) over its
        length scale (activation), ∇g·f⁻ or the least gap over its velocity or length
        scale (grazing); 0 where the run sits on the kink (degenerate, Zeno, simultaneous,
        stick-slide, indeterminate).
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


def coefficient_directions(value: Any, m: int) -> np.ndarray:
    """∂c/∂pⱼ of a coefficient c given as one number for all m contacts (one column p, c = p
    on every contact) or one per contact (m columns), as (p, m)."""
    return np.ones((1, m)) if np.size(value) == 1 else np.eye(m)


def parameter_directions(law: ImpactLaw, m: int) -> np.ndarray:
    """∂E/∂pⱼ for the law's coefficients p (its ``coefficient_key``), as (p, m, m): one
    coefficient for all contacts (ε, a scalar e), one per contact (a vector e) or Frémond's
    m × m matrix, row-major."""
    c = np.asarray(law.coefficients, dtype=float)
    if c.ndim == 2:
        return np.eye(m * m).reshape(m * m, m, m)
    return diagonal(coefficient_directions(c, m))


def diagonal(rows: np.ndarray) -> np.ndarray:
    """(p, m, m): each row of a (p, m) array as a diagonal matrix."""
    out = np.zeros(rows.shape + rows.shape[-1:])
    out[:, np.arange(rows.shape[1]), np.arange(rows.shape[1])] = rows
    return out


FRICTION_PARAMETERS = ("mu", "restitution")
"""The names of Coulomb's parameters in ``sensitivities=``: μ and Newton's e of the normal
rows, as :meth:`impactqp.Coulomb.derivative` names them."""


def _parameters(law: ImpactLaw, m: int) -> dict[str, tuple[np.ndarray, np.ndarray, tuple]]:
    """name → (∂E/∂pⱼ (p, m, m), ∂μ/∂pⱼ (p, m), the parameter's shape) of each parameter of
    the law that a run can be differentiated in."""
    if law.frictional:
        out = {}
        for name in FRICTION_PARAMETERS:
            value = getattr(law, name)
            rows = coefficient_directions(value, m)
            zero = np.zeros_like(rows)
            shape = np.shape(value) if np.size(value) > 1 else ()
            out[name] = (diagonal(zero), rows, shape) if name == "mu" else \
                (diagonal(rows), zero, shape)
        return out
    key = law.coefficient_key
    if not key or law.step_restitution(np.arange(m)) is None:
        return {}
    dE = parameter_directions(law, m)
    return {key: (dE, np.zeros(dE.shape[:2]), np.shape(law.coefficients)
                  if np.size(law.coefficients) > 1 else ())}


class Columns(NamedTuple):
    """The tangent columns of each name the user asked for.

    Attributes
    ----------
    names : tuple of str
    slices : dict
        name → its tangent columns.
    shapes : dict
        name → the shape of its cotangent.
    S0 : (2n, k) ndarray
        The tangents of (q₀, v₀).
    pcols : (p,) int ndarray
        The tangent columns of the law's parameters, in the order of ``names``.
    directions : (p, m, m) ndarray
        ∂E/∂pⱼ: the restitution of the step form (Coulomb's e on the diagonal, acting on
        the normal rows).
    mu_directions : (p, m) ndarray
        ∂μ/∂pⱼ (zero for the frictionless laws).
    """

    names: tuple[str, ...]
    slices: dict[str, slice]
    shapes: dict[str, tuple[int, ...]]
    S0: np.ndarray
    pcols: np.ndarray
    directions: np.ndarray
    mu_directions: np.ndarray


def columns(wrt: Sequence[str], law: ImpactLaw, n: int, m: int) -> Columns:
    """Parse ``sensitivities=`` into tangent columns: ``"q0"`` and ``"v0"`` n each, each
    parameter of the law one per coefficient (``"eps"``, ``"e"`` or ``"E"`` of a
    complementarity law; ``"mu"`` and ``"restitution"`` of Coulomb's).

    Raises
    ------
    InputError
        An unknown or repeated name, or none.
    """
    if isinstance(wrt, str) or not all(isinstance(w, str) for w in wrt):
        raise InputError(f"sensitivities must be a sequence of names like ('q0', 'v0'), got "
                         f"{wrt!r}")
    parameters = _parameters(law, m)
    known = ("q0", "v0") + tuple(parameters)
    bad = [w for w in wrt if w not in known]
    if bad or not wrt or len(set(wrt)) != len(wrt):
        raise InputError(f"sensitivities takes distinct names among {known} for {law.name!r}, "
                         f"got {tuple(wrt)!r}")
    slices, shapes, start = {}, {}, 0
    dE, dmu, pcols = [np.zeros((0, m, m))], [np.zeros((0, m))], []
    for w in wrt:
        size = n if w in ("q0", "v0") else parameters[w][1].shape[0]
        slices[w], start = slice(start, start + size), start + size
        if w in ("q0", "v0"):
            shapes[w] = (n,)
            continue
        dE.append(parameters[w][0])
        dmu.append(parameters[w][1])
        shapes[w] = parameters[w][2]
        pcols.append(np.arange(slices[w].start, slices[w].stop))
    S0 = np.zeros((2 * n, start))
    for w, rows in (("q0", slice(0, n)), ("v0", slice(n, 2 * n))):
        if w in slices:
            S0[rows, slices[w]] = np.eye(n)
    return Columns(tuple(wrt), slices, shapes, S0,
                   np.concatenate(pcols or [np.zeros(0)]).astype(np.int64),
                   np.concatenate(dE), np.concatenate(dmu))


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
        start = 0  # ap holds the parameters' cotangents in the order of the names
        for name in self.cols.names:
            if name == "q0":
                out[name] = ax0[:n].copy()
            elif name == "v0":
                out[name] = ax0[n:].copy()
            else:
                part = self.cols.slices[name]
                size, shape = part.stop - part.start, self.cols.shapes[name]
                piece = ap[start:start + size]
                start += size
                out[name] = float(piece[0]) if shape == () else piece.reshape(shape)
        return out
