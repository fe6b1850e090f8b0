"""Newton's methods for local frictional contact problems (docs/theory.md §15): the
semismooth Newton on Alart–Curnier's function with shifted sparse LU steps, and the
least-squares Newton on the natural map (dense; for rank-deficient W where the first stalls),
with :class:`FrictionData`, the problem's arrays as every friction method uses them.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...kernels.friction import (
    alart_curnier,
    modified_velocity,
    modified_velocity_jacobian,
    natural_map,
    project_cones,
    projection_jacobian,
)
from ...kernels.friction_newton import scales
from . import FrictionProgram

NEWTON_STEPS = 50
"""Most steps of one run of Newton (those that converge here take 5 to 35)."""
LSTSQ_STEPS = 60
"""Most steps of the least-squares Newton."""
LSTSQ_MAX = 600
"""Most unknowns d·m for the least-squares Newton (a dense QR per step: 0.1 s at 858)."""


class FrictionData:
    """The problem's arrays as the friction methods use them, built when first asked for (a
    problem the compiled call certifies never needs its compressed rows): W as compressed rows,
    W dense, and the scale ρ_c of each contact's Alart–Curnier function (:func:`scales`)."""

    def __init__(self, program: FrictionProgram) -> None:
        self.program = program
        self.q = program.q
        self.mu = program.mu
        self.d = program.contact_dim
        self.n = self.q.size
        self.qn = float(np.linalg.norm(self.q)) or 1.0

    @cached_property
    def W(self) -> sp.csr_matrix:
        """W as compressed rows (every entry of a dense W stored: no scan for zeros, which
        costs more than a sweep)."""
        W = self.program.W
        if sp.issparse(W):
            rows = sp.csr_matrix(W, dtype=float)
            rows.sum_duplicates()
            return rows
        n = self.n
        return sp.csr_matrix((np.asarray(W, dtype=float).ravel(), np.tile(np.arange(n), n),
                              np.arange(0, n * n + 1, n)), shape=(n, n))

    @cached_property
    def dense(self) -> np.ndarray:
        """W as a dense C-contiguous float array."""
        W = self.program.W
        return np.ascontiguousarray(W.toarray() if sp.issparse(W) else W, dtype=float)

    @cached_property
    def rho(self) -> np.ndarray:
        return scales(self.W.diagonal(), self.d)

    def velocity(self, r: np.ndarray) -> np.ndarray:
        """u = W r + q."""
        return self.W @ r + self.q

    def error(self, r: np.ndarray) -> float:
        """‖F(r)‖/‖q‖."""
        return float(np.linalg.norm(natural_map(r, self.velocity(r), self.mu, self.d))) / self.qn


def newton(data: FrictionData, r: np.ndarray, tol: float, kappa: float = 1.0,
            max_steps: int = NEWTON_STEPS) -> tuple[np.ndarray, int, bool]:
    """Semismooth Newton on Alart–Curnier's function Φ (docs/theory.md §15) from r: steps
    (J + λI)Δ = −Φ with J = A + B W (A, B block-diagonal, from
    :func:`impactqp.kernels.friction.alart_curnier`) and λ = κ·min(‖Φ‖/‖Φ(0)‖, 10⁻²) (J is
    singular where W is; the shift vanishes with Φ), by sparse LU, then backtracking on ‖Φ‖.

    Stops when the projected r is within tol/2 in ‖F‖/‖q‖ (projecting moves r by up to ‖F‖,
    hence u by up to ‖W‖‖F‖), after ``max_steps`` steps, or when the line search fails.
    Returns r projected onto the cones, the steps done, and whether that r is within tol/2
    (the certificate's figure)."""
    W, q, mu, d, rho = data.W, data.q, data.mu, data.d, data.rho
    n, m = data.n, mu.size
    A = np.empty((m, d, d))
    B = np.empty((m, d, d))
    blocks = (np.arange(m), np.arange(m + 1))
    scale = float(np.linalg.norm(alart_curnier(np.zeros(n), q, mu, rho, d, False, A, B)))
    u = data.velocity(r)
    phi = alart_curnier(r, u, mu, rho, d, True, A, B)
    f = float(np.linalg.norm(phi))
    steps = 0
    while True:
        if np.linalg.norm(natural_map(r, u, mu, d)) <= 0.5 * tol * data.qn:
            rp = project_cones(r, mu, d)
            if data.error(rp) <= 0.5 * tol:
                return rp, steps, True
        if steps == max_steps:
            break
        steps += 1
        shift = kappa * min(f / (scale or 1.0), 1e-2)
        J = (sp.bsr_matrix((A, *blocks), shape=(n, n)) + shift * sp.identity(n)
             + sp.bsr_matrix((B, *blocks), shape=(n, n)) @ W)
        try:
            step = spla.splu(sp.csc_matrix(J)).solve(-phi)
        except RuntimeError:  # an exactly singular J
            break
        t = 1.0
        while t > 1e-8:
            r_try = r + t * step
            u_try = data.velocity(r_try)
            phi_try = alart_curnier(r_try, u_try, mu, rho, d, False, A, B)
            f_try = float(np.linalg.norm(phi_try))
            if f_try <= (1.0 - 1e-4 * t) * f:
                break
            t *= 0.5
        else:
            break  # no descent: stalled
        r, u = r_try, u_try
        phi = alart_curnier(r, u, mu, rho, d, True, A, B)
        f = float(np.linalg.norm(phi))
    return project_cones(r, mu, d), steps, False


def lstsq_newton(data: FrictionData, r: np.ndarray, tol: float) -> tuple[np.ndarray, int, bool]:
    """Semismooth Newton on F(r) = r − P_K(r − ũ(Wr + q)) from r: minimum-norm least-squares
    steps J Δ = −F (LAPACK's rank-revealing gelsy; J is singular where W is) with
    J = I − D_P(I − D_ũ W), and backtracking on ‖F‖. Dense: for at most :data:`LSTSQ_MAX`
    unknowns. Returns what :func:`newton` returns."""
    W, q, mu, d = data.dense, data.q, data.mu, data.d
    n, m = data.n, mu.size
    u = W @ r + q
    F = natural_map(r, u, mu, d)
    f = float(np.linalg.norm(F))
    steps = 0
    while True:
        if f <= 0.5 * tol * data.qn:
            rp = project_cones(r, mu, d)
            if data.error(rp) <= 0.5 * tol:
                return rp, steps, True
        if steps == LSTSQ_STEPS:
            break
        steps += 1
        DP = projection_jacobian(r - modified_velocity(u, mu, d), mu, d)
        DUW = np.einsum("cij,cjk->cik", modified_velocity_jacobian(u, mu, d),
                        W.reshape(m, d, n))
        J = np.einsum("cij,cjk->cik", DP, DUW).reshape(n, n) + np.eye(n)
        J -= sla.block_diag(*DP)
        step = sla.lstsq(J, -F, lapack_driver="gelsy", check_finite=False)[0]
        t = 1.0
        while t > 1e-8:
            r_try = r + t * step
            u_try = W @ r_try + q
            F_try = natural_map(r_try, u_try, mu, d)
            f_try = float(np.linalg.norm(F_try))
            if f_try <= (1.0 - 1e-4 * t) * f:
                break
            t *= 0.5
        else:
            break  # no descent: stalled
        r, u, F, f = r_try, u_try, F_try, f_try
    return project_cones(r, mu, d), steps, False
