"""The defining conditions of De Saxcé's form of Coulomb's law, checked by their inequalities
for the friction certificate (docs/theory.md §15).

Written apart from :mod:`impactqp.kernels.friction` on purpose: the solvers call that
module's projection and modified velocity, and a certificate that recomputed them would
certify a wrong formula there with its own answer. Nothing here projects or calls it.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel


@kernel
def coulomb_violation_sums(r, u, mu, d):
    """How far (r, u) is from K_μ ∋ r ⟂ ũ ∈ K*_μ, ũ = u + μ‖u_T‖e_n, contact by contact:
    the sums over the contacts of the squares of, with ω = √(1 + μ²),

    - cone: max((‖r_T‖ − μ r_n)/ω, −r_n, 0), zero exactly when r ∈ K_μ;
    - dual: max((μ‖ũ_T‖ − ũ_n)/ω, −ũ_n, 0), zero exactly when ũ ∈ K*_μ = K_{1/μ};
    - complementarity: |r·ũ| / (‖r‖ + ‖ũ‖) (0 where both vanish).

    The first two are lower bounds of the distances to the cones (equal beside their
    boundaries). A NaN anywhere gives a NaN sum.

    Returns
    -------
    (cone², dual², complementarity²) summed over the contacts.
    """
    cone = 0.0
    dual = 0.0
    comp = 0.0
    for c in range(mu.size):
        k = c * d
        m = mu[c]
        omega = np.sqrt(1.0 + m * m)
        r_t2 = 0.0
        u_t2 = 0.0
        dot_t = 0.0
        for j in range(1, d):
            r_t2 += r[k + j] * r[k + j]
            u_t2 += u[k + j] * u[k + j]
            dot_t += r[k + j] * u[k + j]
        tilde_n = u[k] + m * np.sqrt(u_t2)  # ũ_T = u_T
        a = max((np.sqrt(r_t2) - m * r[k]) / omega, -r[k], 0.0)
        b = max((m * np.sqrt(u_t2) - tilde_n) / omega, -tilde_n, 0.0)
        dot = abs(r[k] * tilde_n + dot_t)
        size = np.sqrt(r[k] * r[k] + r_t2) + np.sqrt(tilde_n * tilde_n + u_t2)
        e = dot / size if dot > 0.0 else dot  # dot is 0 when both vanish; keeps a NaN
        if np.isnan(a + b + e + r[k] + u[k] + r_t2 + u_t2):
            return np.nan, np.nan, np.nan
        cone += a * a
        dual += b * b
        comp += e * e
    return cone, dual, comp
