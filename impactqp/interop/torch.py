"""impactqp's certified impact map as a torch autograd function (the ``torch`` extra;
docs/interop.rst, docs/theory.md §18–§20).

``f = impact_map(problem, law)`` is ``f(u_minus, params=None) -> u_plus`` (or
``(u_plus, impulses)`` with ``impulses=True``) through :class:`ImpactFunction`, a
:class:`torch.autograd.Function`: the forward pass is a certified :func:`impactqp.solve`,
the backward pass :meth:`impactqp.ImpactDerivative.vjp` at that answer. A u⁻ of shape
(k, n) is a batch of k impacts (solved one by one); a parameter is then either the law's
shape (shared by the rows, its gradient summed over them) or (k, ``*shape``). The backward
pass is not itself differentiable: asked for a second derivative (``create_graph=True``),
it raises :class:`~impactqp.errors.DerivativeUnsupportedError`.

Computation is in float64 on the host; tensors come back in u⁻'s dtype and on its device.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..base.checks import DEFAULT_TOL
from ..derivatives.impact import KINK_TOL
from ..errors import DerivativeUnsupportedError, OptionalDependencyError, ShapeError
from .core import ImpactMap

try:
    import torch
except ImportError as exc:  # pragma: no cover (the extra is installed where tests run)
    raise OptionalDependencyError(
        "impactqp.interop.torch needs torch: pip install 'impactqp[torch]'") from exc

__all__ = ["ImpactFunction", "impact_map"]


def _host(t: torch.Tensor) -> np.ndarray:
    return t.detach().to("cpu", torch.float64).numpy()


def _own_shape(core: ImpactMap, name: str, value: torch.Tensor,
               batch: int | None) -> tuple[int, ...]:
    """The shape of one row's parameter: ``value``'s, less a leading batch dimension."""
    shape, own = tuple(value.shape), core.parameters.get(name)
    return shape[1:] if batch is not None and own is not None and shape == (batch, *own) \
        else shape


def _rows(core: ImpactMap, u: np.ndarray, p: tuple[np.ndarray, ...]) -> list[tuple]:
    """(u⁻, params) of each row of a batch, a parameter shared or given per row."""
    names = tuple(core.parameters)
    return [(row, {k: v if v.shape == core.parameters[k] else v[i]
                   for k, v in zip(names, p)}) for i, row in enumerate(u)]


class ImpactFunction(torch.autograd.Function):
    """``ImpactFunction.apply(impact_map, u_minus, *params) -> (u_plus, impulses)``: a
    certified solve forward, :meth:`impactqp.ImpactDerivative.vjp` backward; ``params`` in
    the order of ``impact_map.parameters``, u⁻ of shape (n,) or (k, n)
    (docs/theory.md §18–§20). Its backward pass refuses ``create_graph=True``
    (:class:`~impactqp.errors.DerivativeUnsupportedError`): no second derivative is made
    up."""

    @staticmethod
    def forward(ctx: Any, core: ImpactMap, u_minus: torch.Tensor,
                *params: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        u, p = _host(u_minus), tuple(_host(v) for v in params)
        rows = _rows(core, np.atleast_2d(u), p)
        out = [core.solve(row, values) for row, values in rows]
        u_plus, lam = np.stack([o[0] for o in out]), np.stack([o[1] for o in out])
        if u.ndim == 1:
            u_plus, lam = u_plus[0], lam[0]
        ctx.core, ctx.batched = core, u.ndim == 2
        ctx.save_for_backward(u_minus, *params)
        like = {"dtype": u_minus.dtype, "device": u_minus.device}
        return torch.as_tensor(u_plus, **like), torch.as_tensor(lam, **like)

    @staticmethod
    def backward(ctx: Any, u_bar: torch.Tensor, lam_bar: torch.Tensor) -> tuple:
        core = ctx.core
        if torch.is_grad_enabled():  # create_graph=True: a second derivative was asked for
            raise DerivativeUnsupportedError(
                f"{core.law.title}: impactqp certifies first derivatives only; the backward "
                "pass of its impact map is not differentiable (create_graph=True)")
        u_minus, *params = ctx.saved_tensors
        u, p = _host(u_minus), tuple(_host(v) for v in params)
        ub, lb = np.atleast_2d(_host(u_bar)), np.atleast_2d(_host(lam_bar))
        u_out = np.empty_like(np.atleast_2d(u))
        p_out = [np.zeros_like(v) for v in p]
        for i, (row, values) in enumerate(_rows(core, np.atleast_2d(u), p)):
            u_out[i], grads = core.vjp(row, values, ub[i], lb[i])
            for j, name in enumerate(core.parameters):
                if p[j].shape == core.parameters[name]:
                    p_out[j] += grads[name]
                else:
                    p_out[j][i] = grads[name]
        u_grad = torch.as_tensor(u_out if ctx.batched else u_out[0], dtype=u_minus.dtype,
                                 device=u_minus.device)
        return (None, u_grad, *(torch.as_tensor(g, dtype=v.dtype, device=v.device)
                                for g, v in zip(p_out, params)))


def impact_map(problem: Any, law: Any, *, impulses: bool = False, backend: str = "auto",
               tol: float = DEFAULT_TOL, kink_tol: float = KINK_TOL) -> Callable[..., Any]:
    """The impact map (u⁻, law parameters) ↦ u⁺ of ``law`` on ``problem``'s M and W, as a
    torch function whose gradient is impactqp's certified VJP (docs/theory.md §18–§20).

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W (fixed) and the u⁻ at which the law's parameters are read.
    law : ImpactLaw
        A law with a derivative (Moreau, Newton, Frémond, the sector law, Coulomb).
    impulses : bool
        Return (u⁺, Λ) instead of u⁺.
    backend, tol, kink_tol
        As for :func:`impactqp.derivative`.

    Returns
    -------
    callable
        ``f(u_minus, params=None)``: ``u_minus`` a tensor of shape (n,) or (k, n),
        ``params`` a dict of some of ``f.parameters`` (name → shape; per row with a leading
        k). At a kink the gradient is the derivative's documented default element
        (docs/theory.md §19).

    Raises
    ------
    DerivativeUnsupportedError
        The law has no derivative (named), when ``f`` is made.
    ShapeError, InputError
        Wrong shapes or unknown parameter names.
    CertificateError
        A solve, or a derivative in the backward pass, fails its certificate.
    """
    core = ImpactMap(problem, law, backend=backend, tol=tol, kink_tol=kink_tol)
    names = tuple(core.parameters)

    def f(u_minus: Any, params: dict[str, Any] | None = None) -> Any:
        u = torch.as_tensor(u_minus)
        if not u.is_floating_point():
            u = u.to(torch.float64)
        if u.ndim not in (1, 2) or u.shape[-1] != core.n:
            raise ShapeError(f"u_minus must have shape ({core.n},) or (k, {core.n}), got "
                             f"{tuple(u.shape)}")
        given = {k: torch.as_tensor(v, dtype=u.dtype, device=u.device)
                 for k, v in (params or {}).items()}
        batch = u.shape[0] if u.ndim == 2 else None
        core.check({name: _own_shape(core, name, v, batch) for name, v in given.items()})
        p = tuple(given[name] if name in given else
                  torch.as_tensor(core.defaults[name], dtype=u.dtype, device=u.device)
                  for name in names)
        u_plus, lam = ImpactFunction.apply(core, u, *p)
        return (u_plus, lam) if impulses else u_plus

    f.parameters = dict(core.parameters)
    f.impact_map = core
    return f
