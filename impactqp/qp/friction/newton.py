"""Newton's methods for local frictional contact problems (docs/theory.md §15): the
semismooth Newton on Alart–Curnier's function with shifted sparse LU steps, and the
least-squares Newton on the natural map (dense; for rank-deficient W where the first stalls),
with :class:`FrictionData`, the problem's arrays as every friction method uses them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ...kernels.friction import (
    alart_curnier,
    kernel_mu,
    modified_velocity,
    natural_map,
    project_cones,
)
from ...kernels.friction_blocks import nonzero_rows
from ...kernels.friction_jacobians import modified_velocity_jacobian, projection_jacobian
from ...kernels.friction_newton import scales
from . import FrictionProgram

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


class ContactBlocks(NamedTuple):
    """W stored in d×d blocks, contact by contact (block compressed rows), every diagonal
    block present: the pattern of Newton's J = A + λI + B W, whose block-diagonal A and B
    scale W's block rows, so J is assembled from it with one product per stored block.

    Attributes
    ----------
    data : (k, d, d) ndarray
        The stored blocks of W.
    indices, indptr : ndarray
        Their block columns and each block row's span, as in scipy's BSR format.
    rows : (k,) ndarray
        The block row (contact) of each stored block.
    diagonal : (m,) ndarray
        Where the diagonal block of each contact is stored.
    csc_order : (k·d·d,) ndarray
        For each entry of the pattern in compressed-column order, its place in the blocks'
        entries flattened, so that J is built in that format without converting.
    csc_indices, csc_indptr : ndarray
        The pattern's rows and columns' spans in compressed-column order.
    """

    data: np.ndarray
    indices: np.ndarray
    indptr: np.ndarray
    rows: np.ndarray
    diagonal: np.ndarray
    csc_order: np.ndarray
    csc_indices: np.ndarray
    csc_indptr: np.ndarray

    @classmethod
    def of(cls, W: sp.csr_matrix, d: int) -> ContactBlocks:
        """The blocks of W (explicit zeros added where a diagonal block is not stored)."""
        n = W.shape[0]
        coo = W.tocoo()
        eye = np.repeat(np.arange(n), d)  # every entry of each diagonal block, as zeros
        cols = (eye // d) * d + np.tile(np.arange(d), n)
        pattern = sp.coo_matrix((np.concatenate([coo.data, np.zeros(eye.size)]),
                                 (np.concatenate([coo.row, eye]),
                                  np.concatenate([coo.col, cols]))),
                                shape=(n, n)).tobsr(blocksize=(d, d))
        pattern.sort_indices()
        rows = np.repeat(np.arange(n // d), np.diff(pattern.indptr))
        diagonal = np.flatnonzero(pattern.indices == rows)
        # the entries numbered 1, 2, … through scipy's conversion give the column order
        places = sp.bsr_matrix((np.arange(1.0, pattern.data.size + 1.0).reshape(
            pattern.data.shape), pattern.indices, pattern.indptr), shape=(n, n)).tocsc()
        places.sort_indices()
        return cls(pattern.data, pattern.indices, pattern.indptr, rows, diagonal,
                   places.data.astype(np.int64) - 1, places.indices, places.indptr)

    def jacobian(self, A: np.ndarray, B: np.ndarray, shift: float) -> sp.csc_matrix:
        """J = A + shift·I + B W (A, B: one d×d block per contact), for a sparse LU."""
        data = np.matmul(B[self.rows], self.data)
        data[self.diagonal] += A + shift * np.eye(A.shape[1])
        n = A.shape[0] * A.shape[1]
        J = sp.csc_matrix((data.ravel()[self.csc_order], self.csc_indices.copy(),
                           self.csc_indptr.copy()), shape=(n, n))
        J.eliminate_zeros()  # rows B_c = 0 (a contact coming apart) add no work to the LU
        return J


class FrictionData:
    """The problem's arrays as the friction methods use them, each built when first asked for
    (a problem the compiled call certifies never needs its compressed rows): W as compressed
    rows, W dense, ‖q‖, and the scale ρ_c of each contact's Alart–Curnier function
    (:func:`scales`)."""

    def __init__(self, program: FrictionProgram) -> None:
        self.program = program
        self.q = program.q
        self.mu = kernel_mu(program.mu)
        self.d = program.contact_dim
        self.n = self.q.size
        self._rows: sp.csr_matrix | None = None
        self._dense: np.ndarray | None = None
        self._qn: float | None = None
        self._rho: np.ndarray | None = None
        self._blocks: ContactBlocks | None = None

    @property
    def W(self) -> sp.csr_matrix:
        """W as compressed rows (a dense W's nonzero entries, found in one compiled pass:
        the price of one dense sweep, where W of contacts is mostly zeros)."""
        if self._rows is None:
            W = self.program.W
            if sp.issparse(W):
                self._rows = sp.csr_matrix(W, dtype=float)
                self._rows.sum_duplicates()
            else:
                indptr, indices, data = nonzero_rows(np.ascontiguousarray(W, dtype=float))
                self._rows = sp.csr_matrix((data, indices, indptr), shape=(self.n, self.n))
        return self._rows

    @property
    def dense(self) -> np.ndarray:
        """W as a dense C-contiguous float array."""
        if self._dense is None:
            W = self.program.W
            self._dense = np.ascontiguousarray(W.toarray() if sp.issparse(W) else W,
                                               dtype=float)
        return self._dense

    @property
    def qn(self) -> float:
        """‖q‖ (1 for q = 0)."""
        if self._qn is None:
            self._qn = norm(self.q) or 1.0
        return self._qn

    @property
    def rho(self) -> np.ndarray:
        if self._rho is None:
            # a contiguous writable copy, the array kernels pass: one compiled signature
            self._rho = scales(self.W.diagonal().copy(), self.d)
        return self._rho

    @property
    def blocks(self) -> ContactBlocks:
        """W in blocks of one contact by another (:class:`ContactBlocks`)."""
        if self._blocks is None:
            self._blocks = ContactBlocks.of(self.W, self.d)
        return self._blocks

    def velocity(self, r: np.ndarray) -> np.ndarray:
        """u = W r + q."""
        return self.W @ r + self.q

    def error(self, r: np.ndarray) -> float:
        """‖F(r)‖/‖q‖."""
        return norm(natural_map(r, self.velocity(r), self.mu, self.d)) / self.qn

    def finished(self, r: np.ndarray, f: float, tol: float) -> np.ndarray | None:
        """r projected onto the cones when ‖F(r)‖ = ``f`` is within tol/2·‖q‖ and the
        projected r too (projecting moves r by up to ‖F‖, hence u by up to ‖W‖‖F‖); else
        None."""
        if f > 0.5 * tol * self.qn:
            return None
        rp = project_cones(r, self.mu, self.d)
        return rp if self.error(rp) <= 0.5 * tol else None


def norm(x: np.ndarray) -> float:
    """‖x‖₂ of a vector, summed by numpy's own loop rather than BLAS: OpenBLAS splits a dot
    product of more than 10⁴ entries over its threads, which then spin on every core
    between calls; on a loaded machine that made each norm of Newton on the 7,002-contact
    granular flow cost ~8 ms and slowed the LU beside it two-fold (docs/theory.md §23)."""
    x = np.ravel(x)
    return math.sqrt(np.einsum("i,i->", x, x))


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
            max_steps: int = NEWTON_STEPS,
            probe: tuple[int, float] | None = None) -> tuple[np.ndarray, int, bool]:
    """Semismooth Newton on Alart–Curnier's function Φ (docs/theory.md §15) from r: steps
    (J + λI)Δ = −Φ with J = A + B W (A, B block-diagonal, from
    :func:`impactqp.kernels.friction.alart_curnier`) and λ = κ·min(‖Φ‖/‖Φ(0)‖, 10⁻²) (J is
    singular where W is; the shift vanishes with Φ), by sparse LU, then backtracking on ‖Φ‖.
    A step the line search rejects outright is solved again with the shift grown by
    :data:`SHIFT_GROWTH` (up to :data:`SHIFT_MAX`); each full step shrinks it back. Each
    step is solved by :func:`newton_step`.

    Stops when the projected r is within tol/2 in ‖F‖/‖q‖ (projecting moves r by up to ‖F‖,
    hence u by up to ‖W‖‖F‖), after ``max_steps`` steps (a rejected step counts), when
    the line search fails at the largest shift, or, with ``probe`` = (k, g), after k steps
    that have not divided ‖F‖ by g (Newton still far from its fast convergence). Returns r
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
    first = -1.0
    while True:
        f_nat = norm(natural_map(r, u, mu, d))
        rp = data.finished(r, f_nat, tol)
        if rp is not None:
            return rp, steps, True
        first = f_nat if first < 0.0 else first
        if steps == max_steps or (probe is not None and steps == probe[0]
                                  and not f_nat * probe[1] <= first):
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
