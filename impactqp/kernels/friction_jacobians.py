"""The derivatives of the closed forms of :mod:`impactqp.kernels.friction` that Newton's steps
on the natural map take (docs/theory.md §15): of the projection onto the friction cones and
of De Saxcé's modified velocity, one d × d block per contact.
"""

from __future__ import annotations

import numpy as np

from .friction import tangent_norm
from .jit import kernel


@kernel
def projection_jacobian(x, mu, d):
    """An element of the (Clarke) Jacobian of P_{K_μ} at x, one d × d block per contact
    (the derivative of the closed form; on a kink, the branch the closed form takes)."""
    m = mu.size
    J = np.zeros((m, d, d))
    for c in range(m):
        k = c * d
        m_ = mu[c]
        xn = x[k]
        t = tangent_norm(x, k, d)
        if t <= m_ * xn:
            for j in range(d):
                J[c, j, j] = 1.0
        elif m_ * t <= -xn:
            continue
        else:
            s = 1.0 / (1.0 + m_ * m_)
            a = (xn + m_ * t) * s
            J[c, 0, 0] = s
            for j in range(1, d):
                w = x[k + j] / t
                J[c, 0, j] = s * m_ * w
                J[c, j, 0] = s * m_ * w
                for i in range(1, d):
                    wi = x[k + i] / t
                    J[c, j, i] = m_ * m_ * s * w * wi - m_ * a / t * w * wi
                J[c, j, j] += m_ * a / t
    return J


@kernel
def modified_velocity_jacobian(u, mu, d):
    """The derivative of u ↦ ũ = u + μ‖u_T‖e_n, one d × d block per contact (the row of
    e_n gains μ u_Tᵀ/‖u_T‖; nothing where u_T = 0)."""
    m = mu.size
    J = np.zeros((m, d, d))
    for c in range(m):
        k = c * d
        for j in range(d):
            J[c, j, j] = 1.0
        t = tangent_norm(u, k, d)
        if t > 0.0:
            for j in range(1, d):
                J[c, 0, j] = mu[c] * u[k + j] / t
    return J


__all__ = ["modified_velocity_jacobian", "projection_jacobian"]
