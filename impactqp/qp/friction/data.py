"""The problem's arrays as every friction method uses them (docs/theory.md §15): q and ‖q‖ for
one solve (:class:`FrictionData`), and what derives from W and μ alone, kept on the problem
between solves (:class:`ProblemArrays`): W by rows, dense, by contacts and in contact blocks
(:class:`ContactBlocks`, the pattern of Newton's Jacobian).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ...kernels.friction import kernel_mu, natural_map, project_cones
from ...kernels.friction_blocks import local_steps, nonzero_rows
from ...kernels.friction_newton import scales
from ...kernels.friction_rows import ContactRows, contact_rows
from . import FrictionProgram


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


class ProblemArrays:
    """What the friction methods derive from a program's W and μ alone, each built when first
    asked for and kept on the program (its ``_arrays``) for the next solve of the same
    W and μ objects (:meth:`holds`): W as compressed rows, W dense, W by contacts with the
    steps of the contacts' fixed points, W in blocks, Alart–Curnier's scales ρ_c and μ as
    the kernels take it. q is not among them: it may be rewritten in place between solves.
    """

    __slots__ = ("W", "mu_given", "d", "mu", "rows", "dense", "contacts", "steps", "rho",
                 "blocks")

    def __init__(self, program: FrictionProgram) -> None:
        self.W, self.mu_given, self.d = program.W, program.mu, program.contact_dim
        self.mu = kernel_mu(program.mu)
        self.rows: sp.csr_matrix | None = None
        self.dense: np.ndarray | None = None
        self.contacts: ContactRows | None = None
        self.steps: np.ndarray | None = None
        self.rho: np.ndarray | None = None
        self.blocks: ContactBlocks | None = None

    def holds(self, program: FrictionProgram) -> bool:
        """Whether these are ``program``'s arrays: the same W and μ objects and d (W edited
        in place is not seen, as :class:`~impactqp.FrictionContactProblem` says)."""
        return (self.W is program.W and self.mu_given is program.mu
                and self.d == program.contact_dim)

    @classmethod
    def of(cls, program: FrictionProgram) -> ProblemArrays:
        """``program``'s kept arrays where it :meth:`holds` them, else new ones, kept on it
        where it takes attributes (a repair's sub-problem, a named tuple, does not: its
        arrays live for the one solve)."""
        kept = getattr(program, "_arrays", None)
        if kept is not None and kept.holds(program):
            return kept
        arrays = cls(program)
        try:
            program._arrays = arrays
        except AttributeError:
            pass
        return arrays


class FrictionData:
    """The problem's arrays as the friction methods use them for one solve: q and ‖q‖, and
    the arrays derived from W and μ (:class:`ProblemArrays`, kept on the program between
    solves), each built when first asked for (a problem the compiled call certifies never
    needs its compressed rows): W as compressed rows, W dense, W by contacts, and the scale
    ρ_c of each contact's Alart–Curnier function (:func:`scales`)."""

    def __init__(self, program: FrictionProgram) -> None:
        self.program = program
        self.q = program.q
        self.arrays = ProblemArrays.of(program)
        self.mu = self.arrays.mu
        self.d = program.contact_dim
        self.n = self.q.size
        self._qn: float | None = None

    @property
    def W(self) -> sp.csr_matrix:
        """W as compressed rows (a dense W's nonzero entries, found in one compiled pass:
        the price of one dense sweep, where W of contacts is mostly zeros)."""
        kept = self.arrays
        if kept.rows is None:
            W = kept.W
            if sp.issparse(W):
                rows = sp.csr_matrix(W, dtype=float)
                rows.sum_duplicates()
            else:
                indptr, indices, data = nonzero_rows(np.ascontiguousarray(W, dtype=float))
                rows = sp.csr_matrix((data, indices, indptr), shape=(self.n, self.n))
            kept.rows = rows
        return kept.rows

    @property
    def dense(self) -> np.ndarray:
        """W as a dense C-contiguous float array."""
        kept = self.arrays
        if kept.dense is None:
            W = kept.W
            kept.dense = np.ascontiguousarray(W.toarray() if sp.issparse(W) else W,
                                              dtype=float)
        return kept.dense

    @property
    def contacts(self) -> ContactRows:
        """W by contacts, as the sweeps read it
        (:func:`~impactqp.kernels.friction_rows.contact_rows`)."""
        kept = self.arrays
        if kept.contacts is None:
            W = self.W
            kept.contacts = contact_rows(W.indptr, W.indices, W.data, self.mu.size, self.d)
        return kept.contacts

    @property
    def steps(self) -> np.ndarray:
        """The step of each contact's projected fixed point in the sweeps
        (:func:`~impactqp.kernels.friction_blocks.local_steps`)."""
        kept = self.arrays
        if kept.steps is None:
            kept.steps = local_steps(self.contacts.diagonal)
        return kept.steps

    @property
    def qn(self) -> float:
        """‖q‖ (1 for q = 0)."""
        if self._qn is None:
            self._qn = norm(self.q) or 1.0
        return self._qn

    @property
    def rho(self) -> np.ndarray:
        kept = self.arrays
        if kept.rho is None:
            # a contiguous writable copy, the array kernels pass: one compiled signature
            kept.rho = scales(self.W.diagonal().copy(), self.d)
        return kept.rho

    @property
    def blocks(self) -> ContactBlocks:
        """W in blocks of one contact by another (:class:`ContactBlocks`)."""
        kept = self.arrays
        if kept.blocks is None:
            kept.blocks = ContactBlocks.of(self.W, self.d)
        return kept.blocks

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
