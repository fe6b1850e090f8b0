"""impactqp's certified impact map as a jax function (the ``jax`` extra; docs/interop.rst,
docs/theory.md §18–§20).

``f = impact_map(problem, law)`` is ``f(u_minus, params=None) -> u_plus`` (or
``(u_plus, impulses)`` with ``impulses=True``), a :func:`jax.custom_vjp` function: the
forward pass is a certified :func:`impactqp.solve` and the backward pass
:meth:`impactqp.ImpactDerivative.vjp` at that answer, both run on the host through
:func:`jax.pure_callback`, so ``f`` works under :func:`jax.jit`, :func:`jax.grad`,
:func:`jax.vjp`, :func:`jax.jacrev` and :func:`jax.vmap` (one host call per row). jax takes
one derivative rule per function and cannot transpose a host callback, so forward mode is a
second function: ``impact_map(problem, law, mode="forward")`` is a :func:`jax.custom_jvp`
function whose tangent is :meth:`impactqp.ImpactDerivative.jvp` (:func:`jax.jvp`,
:func:`jax.jacfwd`). Each refuses the other mode, and second derivatives, with jax's own
error: nothing is made up.

``params`` is a dict of the law's differentiable parameters (``f.parameters``: ``eps``,
``e``, ``E``, ``mu``, ``restitution``); those not given keep the law's values. The host
computes in float64 and returns the dtype of u⁻ (float32 unless ``jax_enable_x64``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..base.checks import DEFAULT_TOL
from ..derivatives.impact import KINK_TOL
from ..errors import InputError, OptionalDependencyError, ShapeError
from .core import ImpactMap

try:
    import jax
    import jax.numpy as jnp
except ImportError as exc:  # pragma: no cover (the extra is installed where tests run)
    raise OptionalDependencyError(
        "impactqp.interop.jax needs jax: pip install 'impactqp[jax]'") from exc

__all__ = ["impact_map"]

VMAP_METHOD = "sequential"
"""How the host callbacks are batched under :func:`jax.vmap`: one call per row."""

MODES = ("reverse", "forward")
"""The derivative rule of the function: impactqp's VJP (a ``custom_vjp``) or its JVP (a
``custom_jvp``); jax cannot take both from one function, since a host callback has no
transpose."""


def _shapes(*arrays: Any) -> tuple[jax.ShapeDtypeStruct, ...]:
    return tuple(jax.ShapeDtypeStruct(np.shape(a), a.dtype) for a in arrays)


class _Host:
    """The host side of the callbacks: arrays in, :class:`ImpactMap` in float64, arrays in
    the callers' dtypes out."""

    def __init__(self, core: ImpactMap) -> None:
        self.core, self.names = core, tuple(core.parameters)

    def _params(self, p: tuple) -> dict[str, np.ndarray]:
        return {k: np.asarray(v, dtype=float) for k, v in zip(self.names, p)}

    def solve(self, u: Any, *p: Any) -> tuple[np.ndarray, np.ndarray]:
        u_plus, lam = self.core.solve(np.asarray(u, dtype=float), self._params(p))
        dtype = np.asarray(u).dtype
        return u_plus.astype(dtype), lam.astype(dtype)

    def vjp(self, u: Any, p: tuple, u_bar: Any, lam_bar: Any) -> tuple[np.ndarray, tuple]:
        u_out, p_out = self.core.vjp(np.asarray(u, dtype=float), self._params(p),
                                     np.asarray(u_bar, dtype=float),
                                     np.asarray(lam_bar, dtype=float))
        return (u_out.astype(np.asarray(u).dtype),
                tuple(np.asarray(p_out[k], dtype=np.asarray(v).dtype)
                      for k, v in zip(self.names, p)))

    def jvp(self, u: Any, p: tuple, du: Any, dp: tuple) -> tuple[np.ndarray, np.ndarray]:
        du_plus, dlam = self.core.jvp(np.asarray(u, dtype=float), self._params(p),
                                      np.asarray(du, dtype=float), self._params(dp))
        dtype = np.asarray(u).dtype
        return du_plus.astype(dtype), dlam.astype(dtype)


def _solver(host: _Host, mode: str) -> Callable[[jax.Array, tuple], tuple]:
    """(u, p) ↦ (u⁺, Λ) through the host, with the certified VJP (``"reverse"``) or JVP
    (``"forward"``) as its derivative rule."""
    core = host.core

    def solve(u: jax.Array, p: tuple) -> tuple[jax.Array, jax.Array]:
        shapes = (jax.ShapeDtypeStruct((core.n,), u.dtype),
                  jax.ShapeDtypeStruct((core.m,), u.dtype))
        return jax.pure_callback(host.solve, shapes, u, *p, vmap_method=VMAP_METHOD)

    if mode == "forward":
        solved = jax.custom_jvp(solve)

        @solved.defjvp
        def tangent(primals: tuple, tangents: tuple) -> tuple:
            (u, p), (du, dp) = primals, tangents
            out = solved(u, p)
            return out, jax.pure_callback(host.jvp, _shapes(*out), u, p, du, dp,
                                          vmap_method=VMAP_METHOD)

        return solved
    solved = jax.custom_vjp(solve)

    def forward(u: jax.Array, p: tuple) -> tuple[tuple[jax.Array, jax.Array], tuple]:
        return solved(u, p), (u, p)

    def backward(res: tuple, cotangents: tuple) -> tuple[jax.Array, tuple]:
        u, p = res
        return jax.pure_callback(host.vjp, (_shapes(u)[0], _shapes(*p)), u, p, *cotangents,
                                 vmap_method=VMAP_METHOD)

    solved.defvjp(forward, backward)
    return solved


def impact_map(problem: Any, law: Any, *, impulses: bool = False, mode: str = "reverse",
               backend: str = "auto", tol: float = DEFAULT_TOL,
               kink_tol: float = KINK_TOL) -> Callable[..., Any]:
    """The impact map (u⁻, law parameters) ↦ u⁺ of ``law`` on ``problem``'s M and W, as a
    jax function whose derivative is impactqp's certified VJP, or JVP (docs/theory.md
    §18–§20).

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W (fixed) and the u⁻ at which the law's parameters are read.
    law : ImpactLaw
        A law with a derivative (Moreau, Newton, Frémond, the sector law, Coulomb).
    impulses : bool
        Return (u⁺, Λ) instead of u⁺ (Λ's cotangent enters the VJP; where Λ is not unique
        its derivative is the minimum-norm element, docs/theory.md §18).
    mode : {"reverse", "forward"}
        ``"reverse"``: a :func:`jax.custom_vjp` function whose backward pass is
        :meth:`impactqp.ImpactDerivative.vjp` (:func:`jax.grad`, :func:`jax.vjp`,
        :func:`jax.jacrev`; jax refuses forward mode on it). ``"forward"``: a
        :func:`jax.custom_jvp` function whose tangent is
        :meth:`impactqp.ImpactDerivative.jvp` (:func:`jax.jvp`, :func:`jax.jacfwd`; jax
        refuses to transpose it, so no :func:`jax.grad`).
    backend, tol, kink_tol
        As for :func:`impactqp.derivative`.

    Returns
    -------
    callable
        ``f(u_minus, params=None)``: ``u_minus`` of shape (n,), ``params`` a dict of some of
        ``f.parameters`` (name → shape). ``f.impact_map`` is the
        :class:`~impactqp.interop.core.ImpactMap` it runs on the host. At a kink the
        derivative is the documented default element (docs/theory.md §19).

    Raises
    ------
    DerivativeUnsupportedError
        The law has no derivative (named), when ``f`` is made.
    InputError
        An unknown ``mode``.
    ShapeError, InputError
        Wrong shapes or unknown parameter names, when ``f`` is traced. A solve or a
        derivative that fails its certificate raises on the host; jax re-raises it as its
        runtime error carrying impactqp's message.
    """
    if mode not in MODES:
        raise InputError(f"mode must be one of {MODES}, got {mode!r}")
    core = ImpactMap(problem, law, backend=backend, tol=tol, kink_tol=kink_tol)
    names = tuple(core.parameters)
    solved = _solver(_Host(core), mode)

    def f(u_minus: Any, params: dict[str, Any] | None = None) -> Any:
        u = jnp.asarray(u_minus)
        if not jnp.issubdtype(u.dtype, jnp.floating):
            u = u.astype(jnp.result_type(float))
        if u.shape != (core.n,):
            raise ShapeError(f"u_minus must have shape ({core.n},), got {u.shape} (batch "
                             "with jax.vmap)")
        given = dict(params or {})
        core.check({k: np.shape(v) for k, v in given.items()})
        p = tuple(jnp.asarray(given[k] if k in given else core.defaults[k], dtype=u.dtype)
                  for k in names)
        u_plus, lam = solved(u, p)
        return (u_plus, lam) if impulses else u_plus

    f.parameters = dict(core.parameters)
    f.impact_map = core
    return f
