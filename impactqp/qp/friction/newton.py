"""Newton's methods for local frictional contact problems (docs/theory.md §15): the
semismooth Newton on Alart–Curnier's function with shifted sparse LU steps, and the
least-squares Newton on the natural map (dense; for rank-deficient W where the first stalls),
on :class:`~.data.FrictionData`, the problem's arrays as every friction method uses them.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...kernels.friction import alart_curnier, modified_velocity, natural_map, project_cones
from ...kernels.friction_jacobians import modified_velocity_jacobian, projection_jacobian
from .data import FrictionData, norm

NEWTON_STEPS = 50
"""Most steps of one run of Newton (those that converge here take 5 to 35)."""
SHIFT_GROWTH = 10.0
"""Factor by which Newton's shift grows after a step the line search rejects outright (and
shrinks, back to κ·min(‖Φ‖/‖Φ(0)‖, 10⁻²), after each full step)."""
SHIFT_MAX = 1.0
"""Largest shift Newton grows to: the order of J = A + B W itself (ρ_c W_cc has mean diagonal
one), beyond which the step is a gradient-like one the line search would have accepted."""
STEP_RESIDUAL = 1e-10
"""Largest ‖JΔ − b‖/‖b‖ of a step from the LU with diagonal pivots (:func:`newton_step`);
above it, or where that LU meets a zero pivot, the step is solved again with partial
pivoting."""
LSTSQ_STEPS = 60
"""Most steps of the least-squares Newton."""
LSTSQ_MAX = 600
"""Most unknowns d·m for the least-squares Newton (a dense QR per step: 0.1 s at 858)."""


def backtrack(r: np.ndarray, step: np.ndarray, f: float,
              residual: Callable[[np.ndarray], np.ndarray]
              ) -> tuple[np.ndarray, np.ndarray, float] | None:
    """Armijo backtracking on ‖residual‖ along ``step`` from r (‖residual(r)‖ = f): the first
    of t = 1, 1/2, … (down to 1e-8) with ‖residual(r + t·step)‖ ≤ (1 − 10⁻⁴t)f, as
    (r + t·step, its residual, its norm); None when there is none (no descent: stalled)."""
    t = 1.0
    while t > 1e-8:
        r_try = r + t * step
        res = residual(r_try)
        f_try = norm(res)
        if f_try <= (1.0 - 1e-4 * t) * f:
            return r_try, res, f_try
        t *= 0.5
    return None


def newton_step(J: sp.csc_matrix, rhs: np.ndarray) -> np.ndarray:
    """Δ with J Δ = rhs by sparse LU (docs/theory.md §23): first in a minimum-degree order of
    the pattern of J + Jᵀ with the pivots taken on the diagonal (J = A + λI + B W has W's
    symmetric block pattern, and its diagonal blocks hold A + λI + B_c W_cc), kept when Δ
    solves the system to :data:`STEP_RESIDUAL`; else, or where a diagonal pivot is zero, in
    COLAMD's column order with partial pivoting (scipy's default). On KaplasTower (1710
    unknowns) a step costs 16 ms against 29 ms.

    Raises
    ------
    RuntimeError
        J is exactly singular (a zero pivot with partial pivoting too).
    """
    try:
        step = spla.splu(J, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                         options={"SymmetricMode": True}).solve(rhs)
        if norm(J @ step - rhs) <= STEP_RESIDUAL * norm(rhs):
            return step
    except RuntimeError:  # a zero pivot on the diagonal
        pass
    return spla.splu(J).solve(rhs)


def newton(data: FrictionData, r: np.ndarray, tol: float, kappa: float = 1.0,
            max_steps: int = NEWTON_STEPS, probe: tuple[int, float] | None = None,
            stall: tuple[int, float, float] | None = None) -> tuple[np.ndarray, int, bool]:
    """Semismooth Newton on Alart–Curnier's function Φ (docs/theory.md §15) from r: steps
    (J + λI)Δ = −Φ with J = A + B W (A, B block-diagonal, from
    :func:`impactqp.kernels.friction.alart_curnier`) and λ = κ·min(‖Φ‖/‖Φ(0)‖, 10⁻²) (J is
    singular where W is; the shift vanishes with Φ), by sparse LU, then backtracking on ‖Φ‖.
    A step the line search rejects outright is solved again with the shift grown by
    :data:`SHIFT_GROWTH` (up to :data:`SHIFT_MAX`); each full step shrinks it back. Each
    step is solved by :func:`newton_step`.

    Stops when the projected r is within tol/2 in ‖F‖/‖q‖ (projecting moves r by up to ‖F‖,
    hence u by up to ‖W‖‖F‖), after ``max_steps`` steps (a rejected step counts), when
    the line search fails at the largest shift, with ``probe`` = (k, g), after k steps
    that have not divided ‖F‖ by g (Newton still far from its fast convergence), or, with
    ``stall`` = (k, g, e), at the first k steps in a row that have not divided ‖F‖ by g
    ending within ‖F‖/‖q‖ ≤ e (Newton stalled near the answer, docs/theory.md §15).
    Returns r
    projected onto the cones, the steps done, and whether that r is within tol/2 (the
    certificate's figure)."""
    q, mu, d, rho = data.q, data.mu, data.d, data.rho
    n, m = data.n, mu.size
    A = np.empty((m, d, d))
    B = np.empty((m, d, d))
    scale = norm(alart_curnier(np.zeros(n), q, mu, rho, d, False, A, B))
    u = data.velocity(r)
    phi = alart_curnier(r, u, mu, rho, d, True, A, B)
    f = norm(phi)
    steps = 0
    boost = 1.0
    errors: list[float] = []  # ‖F‖ at r and after each step
    while True:
        f_nat = norm(natural_map(r, u, mu, d))
        rp = data.finished(r, f_nat, tol)
        if rp is not None:
            return rp, steps, True
        errors.append(f_nat)
        if (steps == max_steps or _slow(errors, probe, only_first=True)
                or (stall is not None and f_nat <= stall[2] * data.qn
                    and _slow(errors, stall[:2], only_first=False))):
            break
        steps += 1
        shift = boost * kappa * min(f / (scale or 1.0), 1e-2)
        try:
            step = newton_step(data.blocks.jacobian(A, B, shift), -phi)
        except RuntimeError:  # an exactly singular J
            break
        found = backtrack(r, step, f, lambda x: alart_curnier(x, data.velocity(x), mu, rho,
                                                              d, False, A, B))
        if found is None:
            if shift >= SHIFT_MAX:
                break  # no descent even with a shift of J's own scale: stalled
            boost *= SHIFT_GROWTH  # a step too long along J's near-null directions
            continue
        if np.array_equal(found[0], r + step):
            boost = max(1.0, boost / SHIFT_GROWTH)  # a full step: back towards Newton's
        r = found[0]
        u = data.velocity(r)
        phi = alart_curnier(r, u, mu, rho, d, True, A, B)
        f = norm(phi)
    return project_cones(r, mu, d), steps, False


def _slow(errors: list[float], window: tuple[int, float] | None, only_first: bool) -> bool:
    """Whether the last k = ``window[0]`` steps of Newton (``errors``: ‖F‖ at its start and
    after each step) have not divided ‖F‖ by g = ``window[1]``: asked after the first k steps
    only when ``only_first`` (:func:`newton`'s probe), else after every step from the k-th
    (its stall)."""
    if window is None:
        return False
    k, gain = window
    steps = len(errors) - 1
    if steps < k or (only_first and steps > k):
        return False
    return not errors[-1] * gain <= errors[-1 - k]


def lstsq_newton(data: FrictionData, r: np.ndarray, tol: float) -> tuple[np.ndarray, int, bool]:
    """Semismooth Newton on F(r) = r − P_K(r − ũ(Wr + q)) from r: minimum-norm least-squares
    steps J Δ = −F (LAPACK's rank-revealing gelsy; J is singular where W is) with
    J = I − D_P(I − D_ũ W), and backtracking on ‖F‖. Dense: for at most :data:`LSTSQ_MAX`
    unknowns. Returns what :func:`newton` returns."""
    W, q, mu, d = data.dense, data.q, data.mu, data.d
    n, m = data.n, mu.size
    u = W @ r + q
    F = natural_map(r, u, mu, d)
    f = norm(F)
    steps = 0
    while True:
        rp = data.finished(r, f, tol)
        if rp is not None:
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
        found = backtrack(r, step, f, lambda x: natural_map(x, W @ x + q, mu, d))
        if found is None:
            break  # no descent: stalled
        r, F, f = found
        u = W @ r + q
    return project_cones(r, mu, d), steps, False
