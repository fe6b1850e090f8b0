"""The impact map as a function of u⁻ and the law's parameters, in numpy: what the jax and
torch adapters call on the host (docs/theory.md §18–§20).

M and W are held fixed (the problem's); u⁻ and the law's differentiable parameters (``eps``
for Moreau's law, ``e`` for local Newton, ``E`` for Frémond's, ``mu`` and ``restitution``
for Coulomb's: the names its derivative lists in ``inputs``) vary. Every evaluation is a
certified :func:`impactqp.solve`; every cotangent is :meth:`impactqp.ImpactDerivative.vjp`
at that answer (the documented default element at a kink, docs/theory.md §19), and a
derivative whose own certificate fails is refused, never returned.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from typing import Any

import numpy as np

from ..base.arrays import as_array
from ..base.checks import DEFAULT_TOL
from ..derivatives.impact import KINK_TOL, ImpactDerivative
from ..errors import CertificateError, InputError, ShapeError
from ..laws.pipeline import solve

DATA = ("u_minus", "M", "W")
"""Inputs of a derivative that are the problem's data, not the law's parameters."""


def rebuilder(law: Any, names: tuple[str, ...]) -> Callable[[dict[str, Any]], Any]:
    """values ↦ ``law`` with the parameters ``names`` set to ``values``, built by its own
    constructor: the names a law's derivative differentiates in are its constructor's
    keywords (``eps``, ``e``, ``E``, ``mu``, ``restitution``); the other keywords keep the
    law's attributes of the same name. The constructor is read once, here.

    Raises
    ------
    InputError
        The law's constructor takes no keyword of one of ``names``, or needs one that is not
        an attribute of the law.
    """
    signature = inspect.signature(type(law))
    unknown = sorted(set(names) - set(signature.parameters))
    if unknown:
        raise InputError(f"{law.title}: its constructor takes no {', '.join(unknown)}, so the "
                         "adapters cannot set it (they rebuild the law by its keywords)")
    kept = {}
    for name, param in signature.parameters.items():
        if name in names or param.kind in (param.VAR_POSITIONAL, param.VAR_KEYWORD):
            continue
        if hasattr(law, name):
            kept[name] = getattr(law, name)
        elif param.default is param.empty:
            raise InputError(f"{law.title}: cannot rebuild it with new parameters, its "
                             f"constructor's {name!r} is not an attribute of the law")
    return lambda values: type(law)(**kept, **values)


class ImpactMap:
    """(u⁻, law parameters) ↦ (u⁺, Λ) of one impact structure and law, with its certified
    VJP and JVP (docs/theory.md §18–§20).

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W (held fixed) and the u⁻ at which the law's derivative is first
        formed, to learn its parameters.
    law : ImpactLaw
        A law with a derivative; its current coefficients are the parameters' defaults.
    backend : str
        As for :func:`impactqp.solve`.
    tol : float
        The solve's certificate tolerance.
    kink_tol : float
        Degeneracy tolerance (docs/theory.md §19).

    Attributes
    ----------
    parameters : dict of str to tuple
        The law's differentiable parameters and their shapes, in a fixed order.
    defaults : dict of str to ndarray
        The law's own values of them.
    n, m : int
        Sizes of u⁺ and Λ.

    Raises
    ------
    DerivativeUnsupportedError
        The law has no derivative (the LZB model, the reflection law, a user's law without a
        ``derivative`` hook): named, at construction.
    """

    def __init__(self, problem: Any, law: Any, *, backend: str = "auto",
                 tol: float = DEFAULT_TOL, kink_tol: float = KINK_TOL) -> None:
        self.problem, self.law, self.backend = problem, law, backend
        self.tol, self.kink_tol = tol, kink_tol
        first = solve(problem, law, backend, tol=tol).derivative(kink_tol=kink_tol)
        first.require()
        values = first.local.values()
        self.parameters = {k: tuple(s) for k, s in first.inputs.items() if k not in DATA}
        self.defaults = {k: np.asarray(values[k], dtype=float).copy() for k in self.parameters}
        self._rebuild = rebuilder(law, tuple(self.parameters))
        self.n, self.m = problem.n_dof, problem.n_impulses

    def __repr__(self) -> str:
        return (f"ImpactMap(law={self.law.name!r}, n={self.n}, m={self.m}, "
                f"parameters={list(self.parameters)})")

    # ------------------------------------------------------------------ arguments
    def check(self, shapes: dict[str, tuple[int, ...]]) -> None:
        """Raise :class:`~impactqp.errors.InputError` for a name that is not one of the
        law's parameters, :class:`~impactqp.errors.ShapeError` for a wrong shape."""
        unknown = sorted(set(shapes) - set(self.parameters))
        if unknown:
            raise InputError(f"{self.law.title} is differentiated in "
                             f"{list(self.parameters) or 'u_minus only'}, not {unknown}")
        for name, shape in shapes.items():
            if tuple(shape) != self.parameters[name]:
                raise ShapeError(f"{name} must have shape {self.parameters[name]}, got "
                                 f"{tuple(shape)}")

    def values(self, params: dict[str, Any] | None) -> dict[str, np.ndarray]:
        """The law's parameters: ``params`` checked against their shapes, the law's own
        values for those not given."""
        given = {k: as_array(k, v) for k, v in (params or {}).items()}
        self.check({k: v.shape for k, v in given.items()})
        return {k: given.get(k, self.defaults[k]) for k in self.parameters}

    def _velocity(self, name: str, value: Any) -> np.ndarray:
        arr = as_array(name, value)
        if arr.shape != (self.n,):
            raise ShapeError(f"{name} must have shape ({self.n},), got {arr.shape}")
        return arr

    # ------------------------------------------------------------------ the map
    def law_at(self, params: dict[str, Any] | None) -> Any:
        """The law with ``params`` (checked; the law itself where they are its own values)."""
        values = self.values(params)
        if all(np.array_equal(values[k], self.defaults[k]) for k in values):
            return self.law
        return self._rebuild(values)

    def _result(self, u_minus: Any, params: dict[str, Any] | None) -> Any:
        law = self.law_at(params)
        problem = self.problem.with_u_minus(self._velocity("u_minus", u_minus))
        return solve(problem, law, self.backend, tol=self.tol)

    def solve(self, u_minus: Any, params: dict[str, Any] | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
        """(u⁺, Λ), certified (:class:`~impactqp.errors.CertificateError` otherwise)."""
        r = self._result(u_minus, params)
        return r.u_plus, r.impulses

    def derivative(self, u_minus: Any, params: dict[str, Any] | None = None
                   ) -> ImpactDerivative:
        """The certified derivative at (u⁻, params); its certificate must pass.

        Raises
        ------
        CertificateError
            The derivative's certificate fails (the solves on the active set have no
            solution to round-off): no cotangent is returned.
        """
        d = self._result(u_minus, params).derivative(kink_tol=self.kink_tol)
        d.require()
        if not d.certificate.ok:
            raise CertificateError(f"{self.law.title}: the derivative's certificate failed, "
                                   f"{d.certificate.summary()}")
        return d

    def vjp(self, u_minus: Any, params: dict[str, Any] | None, u_bar: Any,
            lam_bar: Any = None) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """Cotangents (ū⁻, {parameter: p̄}) for cotangents ū of u⁺ and λ̄ of Λ:
        :meth:`impactqp.ImpactDerivative.vjp` at the answer."""
        out = self.derivative(u_minus, params).vjp(u_plus=u_bar, impulses=lam_bar)
        return out["u_minus"], {k: out[k] for k in self.parameters}

    def jvp(self, u_minus: Any, params: dict[str, Any] | None, du_minus: Any,
            dparams: dict[str, Any] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Tangents (du⁺, dΛ) along du⁻ and the parameters' tangents:
        :meth:`impactqp.ImpactDerivative.jvp` at the answer."""
        d = self.derivative(u_minus, params)
        t = d.jvp(u_minus=du_minus, **(dparams or {}))
        return t.u_plus, t.impulses
