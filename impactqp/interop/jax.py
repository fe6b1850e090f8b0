"""impactqp's certified impact map as a jax function (the ``jax`` extra; docs/interop.rst,
docs/theory.md §18–§20).

``f = impact_map(problem, law)`` is ``f(u_minus, params=None) -> u_plus`` (or
``(u_plus, impulses)`` with ``impulses=True``), a :func:`jax.custom_vjp` function: the
forward pass is a certified :func:`impactqp.solve` and the backward pass
:meth:`impactqp.ImpactDerivative.vjp` at that answer, both run on the host through
:func:`jax.pure_callback`, so ``f`` works under :func:`jax.jit`, :func:`jax.grad`,
:func:`jax.vjp`, :func:`jax.jacrev` and :func:`jax.vmap` (one host call per row). Reverse
mode only: jax refuses forward mode (:func:`jax.jvp`, :func:`jax.jacfwd`) of a
``custom_vjp`` function, and second derivatives stop at the host callback with jax's own
error; :meth:`impactqp.ImpactDerivative.jvp` gives forward tangents directly.

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
from ..errors import OptionalDependencyError, ShapeError
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


def _shapes(*arrays: Any) -> tuple[jax.ShapeDtypeStruct, ...]:
    return tuple(jax.ShapeDtypeStruct(np.shape(a), a.dtype) for a in arrays)


def impact_map(problem: Any, law: Any, *, impulses: bool = False, backend: str = "auto",
               tol: float = DEFAULT_TOL, kink_tol: float = KINK_TOL) -> Callable[..., Any]:
    """The impact map (u⁻, law parameters) ↦ u⁺ of ``law`` on ``problem``'s M and W, as a
    jax function whose gradient is impactqp's certified VJP (docs/theory.md §18–§20).

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W (fixed) and the u⁻ at which the law's parameters are read.
    law : ImpactLaw
        A law with a derivative (Moreau, Newton, Frémond, the sector law, Coulomb).
    impulses : bool
        Return (u⁺, Λ) instead of u⁺ (Λ's cotangent enters the VJP; where Λ is not unique
        its derivative is the minimum-norm element, docs/theory.md §18).
    backend, tol, kink_tol
        As for :func:`impactqp.derivative`.

    Returns
    -------
    callable
        ``f(u_minus, params=None)``: ``u_minus`` of shape (n,), ``params`` a dict of some of
        ``f.parameters`` (name → shape). ``f.impact_map`` is the
        :class:`~impactqp.interop.core.ImpactMap` it runs on the host. At a kink the
        gradient is the derivative's documented default element (docs/theory.md §19).

    Raises
    ------
    DerivativeUnsupportedError
        The law has no derivative (named), when ``f`` is made.
    ShapeError, InputError
        Wrong shapes or unknown parameter names, when ``f`` is traced. A solve or a
        derivative that fails its certificate raises on the host; jax re-raises it as its
        runtime error carrying impactqp's message.
    """
    core = ImpactMap(problem, law, backend=backend, tol=tol, kink_tol=kink_tol)
    names = tuple(core.parameters)

    def host_solve(u: Any, *p: Any) -> tuple[np.ndarray, np.ndarray]:
        u_plus, lam = core.solve(np.asarray(u, dtype=float),
                                 {k: np.asarray(v, dtype=float) for k, v in zip(names, p)})
        dtype = np.asarray(u).dtype
        return u_plus.astype(dtype), lam.astype(dtype)

    def host_vjp(u: Any, p: tuple, u_bar: Any, lam_bar: Any) -> tuple[np.ndarray, tuple]:
        u_out, p_out = core.vjp(np.asarray(u, dtype=float),
                                {k: np.asarray(v, dtype=float) for k, v in zip(names, p)},
                                np.asarray(u_bar, dtype=float),
                                np.asarray(lam_bar, dtype=float))
        return (u_out.astype(np.asarray(u).dtype),
                tuple(np.asarray(p_out[k], dtype=np.asarray(v).dtype) for k, v in zip(names, p)))

    @jax.custom_vjp
    def solved(u: jax.Array, p: tuple) -> tuple[jax.Array, jax.Array]:
        shapes = (jax.ShapeDtypeStruct((core.n,), u.dtype),
                  jax.ShapeDtypeStruct((core.m,), u.dtype))
        return jax.pure_callback(host_solve, shapes, u, *p, vmap_method=VMAP_METHOD)

    def forward(u: jax.Array, p: tuple) -> tuple[tuple[jax.Array, jax.Array], tuple]:
        return solved(u, p), (u, p)

    def backward(res: tuple, cotangents: tuple) -> tuple[jax.Array, tuple]:
        u, p = res
        u_bar, lam_bar = cotangents
        return jax.pure_callback(host_vjp, (_shapes(u)[0], _shapes(*p)), u, p, u_bar,
                                 lam_bar, vmap_method=VMAP_METHOD)

    solved.defvjp(forward, backward)

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
