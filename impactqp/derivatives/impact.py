"""Derivatives of one impact: :class:`ImpactDerivative` (docs/theory.md §18–§20).

The law owns what its map is (its ``derivative`` method returns a
:class:`~impactqp.derivatives.local.LocalMap`); this module checks the tangents and
cotangents a user passes, assembles dense Jacobians from VJPs, and makes the certificate.
A law without a ``derivative`` answers ``"unsupported"``, by name: no finite difference is
ever returned as a derivative.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np

from ..base.arrays import as_array, as_count, finite
from ..base.checks import DEFAULT_TOL
from ..errors import DerivativeUnsupportedError, InputError, ShapeError
from .certificate import DerivativeCertificate, derivative_certificate
from .local import Kink, LinearPiece, LocalMap

KINK_TOL = 1e-9
"""Default tolerance of the degeneracy test: a contact whose scaled Λᵢ and wᵢ are both at
most this (relative to ‖u⁻‖) is on a kink (docs/theory.md §19)."""

OUTPUTS = ("u_plus", "impulses")
"""What the Jacobians differentiate: the post-impact velocity or the impulses."""


def _read(name: str, value: Any) -> np.ndarray:
    """A tangent or cotangent as a finite float array, read only: a float array is checked
    for finiteness alone, anything else goes through :func:`as_array`'s checks."""
    if type(value) is np.ndarray and value.dtype == np.float64:
        finite(name, value)
        return value
    return as_array(name, value, copy=False)


class Tangents(NamedTuple):
    """A JVP's answer.

    Attributes
    ----------
    u_plus : (n,) ndarray
        The tangent of u⁺.
    impulses : (m,) ndarray
        The tangent of Λ.
    """

    u_plus: np.ndarray
    impulses: np.ndarray


class ImpactDerivative:
    """The derivative of an impact law's map (u⁻, M, W, parameter) ↦ (u⁺, Λ) at one answer
    (docs/theory.md §18–§20); made by ``result.derivative()`` and :func:`impactqp.derivative`.

    Parameters
    ----------
    problem : ImpactProblem
    law : ImpactLaw
    u_plus, impulses : ndarray
        The certified answer.
    local : LocalMap or None
        What the law's ``derivative`` hook returned (None: unsupported).
    reason : str
        Why the derivative is unsupported (names the law).
    tol : float or callable
        The certificate's tolerance, or what returns it (read when the certificate is
        built: a result's own certificate is then not built before it is needed).
    solve : callable, optional
        data ↦ (u⁺, Λ): the law at other inputs, for audits of a local map that cannot
        evaluate itself.

    Attributes
    ----------
    status : str
        ``"smooth"``: the answer is inside a cell of the piecewise map and :meth:`jacobian`
        is its exact derivative; ``"kink"``: on the boundary of cells, where
        :meth:`directional` gives the one-sided derivatives, :meth:`limiting_jacobians`
        the elements of the B-subdifferential, and :meth:`jacobian` the documented default
        element (degenerate contacts counted as separating; for the sector law the stable
        sort); ``"unsupported"``: the law has no derivative (``reason`` says why).
    law : str
        The law's name.
    inputs : dict of str to tuple
        What the map is differentiable in, with shapes: ``"u_minus"``, ``"M"``, ``"W"`` and
        the law's parameter (``"eps"``, ``"e"``, ``"E"``) where the law has them.
    kink : Kink or None
    impulses_unique : bool
        Λ is locally unique; when not, impulse derivatives are the minimum-norm element.
    certificate : DerivativeCertificate
    """

    def __init__(self, problem: Any, law: Any, u_plus: np.ndarray, impulses: np.ndarray,
                 local: LocalMap | None, *, reason: str = "",
                 tol: float | Callable[[], float] = DEFAULT_TOL,
                 solve: Any = None) -> None:
        self.problem, self.impact_law, self.law = problem, law, law.name
        self.u_plus, self.impulses = u_plus, impulses
        self.local, self.reason, self._tol, self._solve = local, reason, tol, solve
        if isinstance(local, LinearPiece):
            dense = [np.asarray(A.toarray() if hasattr(A, "toarray") else A, dtype=float)
                     for A in (problem.M, problem.W)]
            local.with_problem(*dense)

    @property
    def status(self) -> str:
        return "unsupported" if self.local is None else self.local.status

    @property
    def inputs(self) -> dict[str, tuple[int, ...]]:
        return {} if self.local is None else dict(self.local.inputs)

    @property
    def kink(self) -> Kink | None:
        return None if self.local is None else self.local.kink

    @property
    def impulses_unique(self) -> bool:
        return self.local is not None and self.local.impulses_unique

    @property
    def tol(self) -> float:
        """The certificate's tolerance (the solve's)."""
        return self._tol() if callable(self._tol) else self._tol

    @cached_property
    def certificate(self) -> DerivativeCertificate:
        return derivative_certificate(self, self.tol)

    def require(self) -> None:
        """Raise :class:`DerivativeUnsupportedError` when the law has no derivative."""
        if self.local is None:
            raise DerivativeUnsupportedError(self.reason)

    # ------------------------------------------------------------------ arguments
    def _tangents(self, given: dict[str, Any]) -> dict[str, np.ndarray]:
        self.require()
        out = {}
        for name, value in given.items():
            if value is None:
                continue
            shape = self._shape_of(name)
            arr = _read(name, value)
            if arr.shape != shape:
                raise ShapeError(f"the tangent of {name} must have shape {shape}, got "
                                 f"{arr.shape}")
            out[name] = arr
        return out

    def _shape_of(self, name: str) -> tuple[int, ...]:
        if name not in self.local.inputs:
            raise InputError(f"{self.impact_law.title} is differentiated with respect to "
                             f"{', '.join(map(repr, self.local.inputs))}, not {name!r}")
        return self.local.inputs[name]

    def _output(self, of: str) -> int:
        if of not in OUTPUTS:
            raise InputError(f"of must be one of {OUTPUTS}, got {of!r}")
        return self.u_plus.size if of == "u_plus" else self.impulses.size

    # ------------------------------------------------------------------ derivatives
    def jvp(self, **tangents: Any) -> Tangents:
        """Tangents (du⁺, dΛ) of the default element along the given input tangents
        (keywords ``u_minus``, ``M``, ``W``, the law's parameter; missing ones are zero)."""
        return Tangents(*self.local.jvp(self._tangents(tangents)))

    def vjp(self, u_plus: Any = None, impulses: Any = None) -> dict[str, np.ndarray]:
        """Cotangents of every input for cotangents of u⁺ and Λ (the transpose of
        :meth:`jvp`, consistent with it to round-off)."""
        self.require()
        ub = np.zeros((1, self.u_plus.size)) if u_plus is None else \
            self._cotangent("u_plus", u_plus, self.u_plus.size)[None]
        lb = np.zeros((1, self.impulses.size)) if impulses is None else \
            self._cotangent("impulses", impulses, self.impulses.size)[None]
        return {k: v[0] for k, v in self.local.vjp(ub, lb).items()}

    @staticmethod
    def _cotangent(name: str, value: Any, size: int) -> np.ndarray:
        arr = _read(name, value)
        if arr.shape != (size,):
            raise ShapeError(f"the cotangent of {name} must have shape ({size},), got "
                             f"{arr.shape}")
        return arr

    def jacobian(self, wrt: str = "u_minus", of: str = "u_plus") -> np.ndarray:
        """The dense Jacobian ∂(of)/∂(wrt), shape (size of ``of``, ``*wrt.shape``): the
        map's derivative where smooth, the default element at a kink. With ``of =
        "impulses"`` where Λ is not unique, the minimum-norm element
        (``impulses_unique`` says so)."""
        self.require()
        size = self._output(of)
        self._shape_of(wrt)
        eye, zeros = np.eye(size), np.zeros((size, self._output(
            "impulses" if of == "u_plus" else "u_plus")))
        ub, lb = (eye, zeros) if of == "u_plus" else (zeros, eye)
        return self.local.vjp(ub, lb)[wrt]

    def directional(self, **tangents: Any) -> Tangents:
        """The one-sided derivative along the given tangents (docs/theory.md §19): at a
        kink, the limit of (map(x + t·d) − map(x))/t as t ↓ 0; the JVP where smooth."""
        return Tangents(*self.local.directional(self._tangents(tangents)))

    def limiting_jacobians(self, cap: int = 64, wrt: str = "u_minus",
                           of: str = "u_plus") -> list[np.ndarray]:
        """The Jacobians of the cells meeting at the answer (the elements of the
        B-subdifferential, docs/theory.md §19), at most ``cap``; one where smooth."""
        self.require()
        cap = as_count("cap", cap, minimum=1)
        size = self._output(of)
        self._shape_of(wrt)
        other = np.zeros((size, self._output("impulses" if of == "u_plus" else "u_plus")))
        ub, lb = (np.eye(size), other) if of == "u_plus" else (other, np.eye(size))
        return [piece.vjp(ub, lb)[wrt] for piece in self.local.pieces(cap)]

    def evaluate(self, data: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        """(u⁺, Λ) of the law at other inputs (audits): the local map's own evaluation, else
        the law solved on the problem with u⁻ (and M, W) replaced."""
        out = self.local.evaluate(data)
        if out is None:
            out = self._solve(data)
        return out

    def __repr__(self) -> str:
        if self.local is None:
            return f"ImpactDerivative(law={self.law!r}, status='unsupported')"
        return (f"ImpactDerivative(law={self.law!r}, status={self.status!r}, "
                f"inputs={list(self.local.inputs)}, margin={self.local.margin:.3g})")


def derivative_of(result: Any, *, kink_tol: float = KINK_TOL) -> ImpactDerivative:
    """The derivative of a certified impact result (``result.derivative()``): the law's
    ``derivative`` hook at the result's answer, or ``"unsupported"`` by name."""
    law, problem = result.impact_law, result.problem
    if type(kink_tol) is not float:  # the default needs no conversion
        kink_tol = float(as_array("kink_tol", kink_tol))
    if not 0.0 <= kink_tol < 1.0:
        raise InputError(f"kink_tol must lie in [0, 1), got {kink_tol!r}")

    def solve(data: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        if law.forms:
            raise DerivativeUnsupportedError(
                f"{law.title}: its local map gives no evaluation to audit against")
        p = type(problem)(data.get("M", problem.M), data.get("W", problem.W),
                          data["u_minus"], contact_dim=problem.contact_dim)
        answer = law.answer_of(p, law.closed_form(p))
        return answer.u_plus, answer.impulses

    local = law.derivative(problem, result, kink_tol=kink_tol)
    reason = "" if local is not None else (
        f"{law.title} ({law.name!r}) has no derivative: it defines no `derivative` hook"
        " (impactqp never returns a finite difference as a derivative)")
    return ImpactDerivative(problem, law, result.u_plus, result.impulses, local,
                            reason=reason, tol=lambda: result.certificate.tol, solve=solve)
