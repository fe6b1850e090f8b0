"""The certificate of a derivative: the project's :class:`~impactqp.results.Certificate`
with the cell's margin, the residual and condition of the linear solves, and an audit
against finite differences taken inside the cell (docs/theory.md §20).
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ..base.arrays import as_count
from ..base.checks import Certificate

AUDIT_STEP = 1e-5
"""Largest relative step of an audit's central differences (smaller inside a thin cell)."""

KINK_STEP = 1e-7
"""Largest relative step of an audit's one-sided differences at a kink."""


class Audit(NamedTuple):
    """The outcome of :meth:`DerivativeCertificate.audit`.

    Attributes
    ----------
    ok : bool
        Every direction agreed within ``rtol``.
    errors : ndarray
        ‖finite difference − derivative‖ / (‖u⁻‖ + ‖u⁺‖) per direction (of u⁺; of Λ too,
        relative to ‖Λ‖, where Λ is unique).
    step : float
        The relative step used.
    rtol : float
    one_sided : bool
        A kink: one-sided differences of u⁻ and the law's parameter against the directional
        derivative.
    """

    ok: bool
    errors: np.ndarray
    step: float
    rtol: float
    one_sided: bool


def random_direction(rng: np.random.Generator, name: str, value: np.ndarray) -> np.ndarray:
    """A random direction of the size of ``value``; for M, symmetric and scaled like M
    (D X D with D = diag(√Mᵢᵢ), ‖X‖ = 1), so that M + t·dM stays positive definite for
    small t whatever the spread of the masses."""
    d = rng.standard_normal(value.shape)
    if name == "M":
        D = np.sqrt(np.abs(np.diag(value)))
        d = 0.5 * (d + d.T)
        return D[:, None] * (d / np.linalg.norm(d)) * D[None, :]
    size = float(np.linalg.norm(value)) or 1.0
    return d * (size / (float(np.linalg.norm(d)) or 1.0))


class DerivativeCertificate(Certificate):
    """What the library recomputes about a derivative (docs/theory.md §20).

    Residuals (judged): ``linear_solve``, the relative residual of the solves on the active
    set (a right-hand side outside the range of G_AA shows here); ``supported`` (0, or
    +inf for a law without derivative). Reported: ``margin``, the radius, relative to
    ‖u⁻‖, of the cell in which the Jacobian is exactly the map's derivative (0 at a kink),
    and ``condition``, the condition estimate of those solves. :meth:`audit` checks random
    directions against finite differences.

    Parameters
    ----------
    values : dict
        The judged residuals.
    tol : float
    reported, extras : dict
        Figures shown (margin, condition) and the rest (status, kink).
    owner : ImpactDerivative
        The derivative it certifies (audits evaluate through it).
    """

    def __init__(self, values: dict, tol: float, *, reported: dict, extras: dict,
                 owner: Any) -> None:
        super().__init__(values, tol, reported=reported, extras=extras)
        self.__dict__["owner"] = owner

    def audit(self, n: int = 8, *, seed: int = 0, rtol: float = 1e-6) -> Audit:
        """Check ``n`` random directions against finite differences of the map.

        Inside the cell (smooth), central differences along random directions of every
        input (u⁻, M symmetric, W, the law's parameter), with a step below the margin; at a
        kink, one-sided differences along directions of u⁻ and the law's parameter against
        :meth:`~impactqp.derivatives.impact.ImpactDerivative.directional`. The map is
        evaluated independently of the derivative: through the library's LCP solver (the
        complementarity laws), the closed form (the sector law) or the law's solve.
        """
        owner = self.owner
        owner.require()
        n = as_count("n", n, minimum=1)
        rng = np.random.default_rng(seed)
        local = owner.local
        base = {k: np.asarray(v, dtype=float) for k, v in local.values().items()}
        kink = owner.status == "kink"
        step = min(KINK_STEP if kink else AUDIT_STEP, 0.25 * local.reach) or KINK_STEP
        u0, l0 = owner.u_plus, owner.impulses
        scale_u = float(np.linalg.norm(base["u_minus"]) + np.linalg.norm(u0)) or 1.0
        scale_l = float(np.linalg.norm(l0)) or 1.0
        errors = np.empty(n)
        for j in range(n):
            t = {}
            for name, value in base.items():
                if kink and name in ("M", "W") or (
                        local.audit_inputs is not None and name not in local.audit_inputs):
                    continue
                t[name] = random_direction(rng, name, value)
            plus = owner.evaluate({k: v + step * t.get(k, 0.0) for k, v in base.items()})
            if kink:
                fd_u, fd_l = (plus[0] - u0) / step, (plus[1] - l0) / step
                du, dl = local.directional(t)
            else:
                minus = owner.evaluate({k: v - step * t.get(k, 0.0) for k, v in base.items()})
                fd_u = (plus[0] - minus[0]) / (2 * step)
                fd_l = (plus[1] - minus[1]) / (2 * step)
                du, dl = local.jvp(t)
            err = float(np.linalg.norm(fd_u - du)) / scale_u
            if local.impulses_unique and dl.size:
                err = max(err, float(np.linalg.norm(fd_l - dl)) / scale_l)
            errors[j] = err
        return Audit(bool(np.all(errors <= rtol)), errors, step, rtol, kink)


def derivative_certificate(owner: Any, tol: float) -> DerivativeCertificate:
    """The certificate of ``owner``'s derivative, recomputed from its local map."""
    local = owner.local
    extras: dict[str, Any] = {"status": owner.status}
    if local is None:
        return DerivativeCertificate({"supported": np.inf}, tol, reported={},
                                     extras={**extras, "reason": owner.reason}, owner=owner)
    extras["kink"] = local.kink
    extras["impulses_unique"] = local.impulses_unique
    return DerivativeCertificate({"supported": 0.0, "linear_solve": local.residual}, tol,
                                 reported={"margin": local.margin,
                                           "condition": local.condition},
                                 extras=extras, owner=owner)
