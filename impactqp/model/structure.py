"""The data of an impact that do not depend on u⁻: M and W, validated and factorized once
(docs/theory.md §1).

An :class:`ImpactStructure` is shared by every problem built with
:meth:`~impactqp.ImpactProblem.with_u_minus`, so a parameter sweep or a simulator pays for
validation, the factorization of M and the Delassus matrix only once.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg import lapack

from ..base.arrays import Matrix, as_dense, as_matrix
from ..base.cholesky import cholesky_solve
from ..base.definite import symmetric_ldl
from ..base.rowwise import row_max, row_sum
from ..errors import MassMatrixError, ShapeError
from ..kernels.impact import pack_operators
from ..kernels.units import contact_units
from .validation import check_contact_dim, check_delassus_diagonal, check_mass, check_pivots


@dataclass(frozen=True)
class ChainInfo:
    """Marks a problem as a 1-D chain (docs/theory.md §5): ball masses and the fixed walls.

    Attributes
    ----------
    masses : (N,) ndarray
        Ball masses, left to right.
    left_wall, right_wall : bool
        Fixed walls touching the first / last ball.
    """

    masses: np.ndarray
    left_wall: bool = False
    right_wall: bool = False


class ImpactStructure:
    """M and W of an impact, validated and factorized once (docs/theory.md §1).

    Parameters
    ----------
    M : (n, n) array_like or scipy.sparse matrix
        Mass matrix, symmetric positive definite.
    W : (n, m) array_like or scipy.sparse matrix
        Generalized force directions, one column per closed contact; ``m = 0`` is allowed.
    contact_dim : {1, 2, 3}
        Columns of W per contact (docs/theory.md §16): 1 for frictionless contacts (one
        normal column each, the default), 2 or 3 for frictional ones (the normal column
        first, then the tangent columns; 2 in the plane). ``m`` counts columns either way.
    chain : ChainInfo, optional
        Marks W as the chain's directions
        (:func:`!impactqp.model.chain_structure.chain_directions`), which lets chains use
        O(N) operators and the isotonic backend. The builders make a
        :class:`!impactqp.model.chain_structure.ChainStructure` instead, which checks the
        masses in O(N) and forms M and W only when they are asked for.

    Raises
    ------
    ShapeError, NonFiniteError, MassMatrixError, InputError
        On malformed input (all ``ValueError`` subclasses naming the argument).
    """

    _diag: np.ndarray | None = None
    """M's diagonal when M is stored as a diagonal (sparse diagonal M, chains), else None."""

    contact_dim: int = 1
    """Columns of W per contact: 1 frictionless, 2 or 3 frictional (docs/theory.md §16)."""

    def __init__(self, M: Matrix, W: Matrix, *, chain: ChainInfo | None = None,
                 contact_dim: int = 1) -> None:
        contact_dim = check_contact_dim(contact_dim, chain)
        M, W = as_matrix("M", M), as_matrix("W", W)
        self.sparse = sp.issparse(M) or sp.issparse(W)
        if self.sparse:
            M, W = sp.csc_matrix(M), sp.csc_matrix(W)
        if M.ndim != 2 or M.shape[0] != M.shape[1] or M.shape[0] == 0:
            raise ShapeError(f"M must be a non-empty square (n, n) matrix, got shape {M.shape}")
        n = M.shape[0]
        if W.ndim == 1 and W.size == 0:
            W = np.zeros((n, 0))
        if W.ndim != 2 or W.shape[0] != n:
            raise ShapeError(f"W must have shape (n, m) = ({n}, m) to match M, got {W.shape}")
        if W.shape[1] % contact_dim:
            raise ShapeError(f"W has {W.shape[1]} columns, not a multiple of contact_dim = "
                             f"{contact_dim}: give {contact_dim} columns per contact (the "
                             "normal first, then the tangents)")
        self.M, self.W = M, W
        self.n, self.m = n, W.shape[1]
        self.chain = chain
        self.contact_dim = contact_dim
        check_mass(M, self.sparse)
        self._factorize()
        col_norms = np.sqrt(np.asarray(abs(W).power(2).sum(axis=0)).ravel()) if self.sparse \
            else np.linalg.norm(W, axis=0)
        if np.any(col_norms == 0):
            raise ShapeError(f"W column(s) {np.flatnonzero(col_norms == 0).tolist()} are zero: "
                             "every contact needs a non-zero force direction")
        if self.sparse and not self.diagonal_mass:
            check_pivots(self._lu.U.diagonal())
        else:
            check_delassus_diagonal(lambda: self.delassus_diagonal)

    @property
    def n_contacts(self) -> int:
        """Number of contacts: the columns of W over :attr:`contact_dim`."""
        return self.m // self.contact_dim

    @cached_property
    def normal_structure(self) -> ImpactStructure:
        """The frictionless structure of the normal columns W[:, ::d] (itself when d = 1):
        M and the normal directions, for what only the normals decide (T_C, z, γ_n ≥ 0)."""
        d = self.contact_dim
        if d == 1:
            return self
        W = self.W[:, ::d] if not self.sparse else sp.csc_matrix(self.W)[:, ::d]
        return ImpactStructure(self.M, W)

    def _factorize(self) -> None:
        if self.sparse:
            diag = self.M.diagonal()
            offdiag = self.M - sp.diags(diag)
            self.diagonal_mass = offdiag.nnz == 0 or abs(offdiag).max() == 0
            if self.diagonal_mass:
                if np.any(diag <= 0):
                    bad = np.flatnonzero(diag <= 0)[:5].tolist()
                    raise MassMatrixError(f"M must be positive definite; diagonal entries {bad} "
                                          "are not positive")
                self._diag = diag
                return
            lu, definite = symmetric_ldl(self.M)
            if not definite:
                raise MassMatrixError("M must be positive definite; its LDLᵀ factorization has "
                                      "a non-positive pivot")
            self._lu = lu
        else:
            self.diagonal_mass = bool(np.count_nonzero(self.M - np.diag(np.diag(self.M))) == 0)
            # LAPACK directly: the same factorization without scipy.linalg's per-call checks,
            # which cost more than the factorization itself for the small M of most impacts
            chol, info = lapack.dpotrf(self.M, lower=1, clean=1)
            if info == 0:
                self._chol = chol
            else:
                eig = np.linalg.eigvalsh(self.M).min()
                raise MassMatrixError("M must be positive definite; its smallest eigenvalue is "
                                      f"{eig:.3g}") from None

    # --- linear algebra in the kinetic metric -------------------------------------------
    def solve_mass(self, x: np.ndarray) -> np.ndarray:
        """Return M⁻¹x for a vector or a matrix of right-hand sides."""
        if self._diag is not None:  # a stored diagonal M (sparse or a chain): a division
            return x / self._diag[:, None] if x.ndim == 2 else x / self._diag
        if self.sparse:
            return self._lu.solve(np.asarray(x, dtype=float))
        if np.ndim(x) == 2:  # potrs' two triangular solves, a small one in the calling thread
            return cholesky_solve(self._chol, cholesky_solve(self._chol, x), transpose=True)
        return lapack.dpotrs(self._chol, x, lower=1)[0]  # info ≠ 0 only for bad shapes

    @cached_property
    def mass_diagonal(self) -> np.ndarray | None:
        """The diagonal of M when M is diagonal (chains), else None."""
        return np.asarray(self.M.diagonal()).ravel() if self.diagonal_mass else None

    def mass_rows(self, X: np.ndarray) -> np.ndarray:
        """M applied to a vector or to every row of X (M is symmetric)."""
        d = self.mass_diagonal
        if d is not None:
            return X * d
        return X @ self.M if not self.sparse else np.asarray((self.M @ X.T).T)

    @np.errstate(over="ignore", under="ignore", invalid="ignore")  # NaN rows give NaN norms
    def kinetic_norms(self, X: np.ndarray) -> np.ndarray:
        """‖x‖ = sqrt(xᵀMx) of a vector or of every row of X, without overflow or underflow
        (each row is divided by its largest entry before it is squared whenever the plain
        sum of squares would lose range)."""
        q = row_sum(self.mass_rows(X) * X)
        if X.ndim == 1:
            if 1e-250 < q < np.inf:
                return np.sqrt(q)
        elif np.isfinite(q).all() and q.min(initial=np.inf) > 1e-250:
            return np.sqrt(q)
        s = row_max(np.abs(X))
        safe = np.where(s > 0, s, 1.0)
        Y = X / (safe[..., None] if X.ndim == 2 else safe)
        return s * np.sqrt(np.maximum(row_sum(self.mass_rows(Y) * Y), 0.0))

    def Wt_times(self, U: np.ndarray) -> np.ndarray:
        """Contact velocities γ = Wᵀu of a vector or of every row of U (for a chain, the
        differences of neighbouring velocities, in O(N) without a matrix)."""
        c = self.chain
        if c is None:
            return np.asarray(self.W.T @ U.T).T
        parts = [U[..., :1]] if c.left_wall else []
        parts.append(np.diff(U, axis=-1))
        if c.right_wall:
            parts.append(-U[..., -1:])
        return parts[0] if len(parts) == 1 else np.concatenate(parts, axis=-1)

    def impulse_velocity(self, Lam: np.ndarray) -> np.ndarray:
        """Velocity jump M⁻¹WΛ of an impulse vector or of every row of Lam (docs/theory.md §1;
        for a chain, ball j gets (L_{j−1} − L_j)/m_j from the impulses L on its two sides)."""
        c = self.chain
        if c is None:
            return np.asarray(self.Minv_W @ Lam.T).T
        n = self.n
        L = np.zeros(Lam.shape[:-1] + (n + 1,))
        L[..., (0 if c.left_wall else 1):(n + 1 if c.right_wall else n)] = Lam
        return (L[..., :-1] - L[..., 1:]) / c.masses

    @cached_property
    def dense_mass(self) -> np.ndarray:
        """M as a C-contiguous float array (dense problems): the kernels' operand."""
        return np.ascontiguousarray(as_dense(self.M), dtype=float)

    @cached_property
    def dense_Wt(self) -> np.ndarray:
        """Wᵀ as a C-contiguous float array (dense problems): the kernels' operand."""
        return np.ascontiguousarray(as_dense(self.W).T, dtype=float)

    @cached_property
    def dense_Minv_W(self) -> np.ndarray:
        """M⁻¹W as a C-contiguous float array (dense problems): the kernels' operand."""
        return np.ascontiguousarray(as_dense(self.Minv_W), dtype=float)

    @cached_property
    def kernel_pack(self) -> np.ndarray:
        """M, Wᵀ, M⁻¹W, G and the contact scales packed for the compiled impact solve
        (:func:`!impactqp.kernels.impact.pack`; dense problems)."""
        return pack_operators(self.dense_mass, self.dense_Wt.T, self.dense_Minv_W,
                              as_dense(self.delassus), self.certificate_Minv_W)

    @cached_property
    def certificate_Minv_W(self) -> np.ndarray:
        """M⁻¹W for certificates, by LU of M: not the solvers' (docs/theory.md §8)."""
        return np.ascontiguousarray(np.linalg.solve(self.dense_mass, self.dense_Wt.T))

    @cached_property
    def warm_support(self) -> np.ndarray:
        """The support of the last compiled impact solve: the next one starts from it."""
        return np.zeros(self.m, dtype=bool)

    @cached_property
    def contact_rows(self) -> Matrix:
        """Wᵀ as the constraint rows of the velocity program (CSC when sparse), kept once."""
        return sp.csc_matrix(self.W.T) if self.sparse else self.W.T

    @cached_property
    def cholesky_factor(self) -> np.ndarray:
        """Lower Cholesky factor L of a dense M (M = LLᵀ)."""
        if self.sparse:
            raise ValueError("the dense Cholesky factor is only kept for dense problems")
        return self._chol

    @cached_property
    def scaled_W(self) -> np.ndarray:
        """B = L⁻¹W, so that G = BᵀB (dense problems): the basis of the NNLS paths."""
        return cholesky_solve(self.cholesky_factor, self.W)

    @cached_property
    def Minv_W(self) -> Matrix:
        """M⁻¹W (sparse when M is diagonal and W sparse, dense otherwise)."""
        if self.sparse and self.diagonal_mass:
            return sp.csc_matrix(sp.diags(1.0 / self._diag) @ self.W)
        if not self.sparse and self._diag is None:  # L⁻ᵀB: the second half of solve_mass
            return cholesky_solve(self.cholesky_factor, self.scaled_W, transpose=True)
        return self.solve_mass(as_dense(self.W))

    @cached_property
    def delassus(self) -> Matrix:
        """Delassus matrix G = WᵀM⁻¹W (docs/theory.md §1), symmetric positive semidefinite."""
        if self.sparse and self.diagonal_mass:
            G = sp.csc_matrix(self.W.T @ self.Minv_W)
            return (G + G.T) * 0.5
        if not self.sparse:
            B = self.scaled_W
            return B.T @ B
        G = np.asarray(self.W.T @ self.Minv_W)
        return 0.5 * (G + G.T)

    @cached_property
    def contact_delassus(self) -> tuple[Matrix, np.ndarray]:
        """(G̃, s), kept: G in each frictional contact's own unit, G̃ = D G D with
        D = diag(1/s) and sᵢ = √G_nn of the contact of entry i
        (:func:`impactqp.kernels.units.contact_units`, docs/theory.md §16)."""
        s = contact_units(np.ascontiguousarray(self.delassus_diagonal, dtype=float),
                          self.contact_dim)
        G = self.delassus
        if sp.issparse(G):
            D = sp.diags(1.0 / s)
            return sp.csc_matrix(D @ G @ D), s
        return G / np.outer(s, s), s

    @cached_property
    def full_column_rank(self) -> bool:
        """W has independent columns, so the Λ of M(u⁺ − u⁻) = WΛ is unique."""
        return self.m <= self.n and int(np.linalg.matrix_rank(as_dense(self.W))) == self.m

    @cached_property
    def delassus_lu(self):
        """Sparse LU factorization of G, or None when G is singular (redundant contacts)."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", spla.MatrixRankWarning)
            try:
                return spla.splu(sp.csc_matrix(self.delassus))
            except RuntimeError:
                return None

    @cached_property
    def contact_scale(self) -> np.ndarray:
        """sᵢ = sqrt(Gᵢᵢ): abs(γᵢ) ≤ sᵢ‖u‖ (the unit of contact velocities in certificates)."""
        return np.sqrt(self.delassus_diagonal)

    @cached_property
    def inverse_masses(self) -> np.ndarray:
        """1/mᵢ of a chain's balls (chains only): the chain's M⁻¹."""
        return 1.0 / self.chain.masses

    @cached_property
    def delassus_diagonal(self) -> np.ndarray:
        """Diagonal of G: the squared M⁻¹-length of each contact direction, without forming
        G (a chain's gap i has 1/mᵢ + 1/mᵢ₊₁, a wall 1/m of its ball)."""
        c = self.chain
        if c is not None:
            inv, lo = self.inverse_masses, int(c.left_wall)
            out = np.empty(self.m)  # written in place: no concatenated copy of N entries
            np.add(inv[:-1], inv[1:], out=out[lo:lo + inv.size - 1])
            if c.left_wall:
                out[0] = inv[0]
            if c.right_wall:
                out[-1] = inv[-1]
            return out
        if not self.sparse:
            return np.einsum("ij,ij->j", self.scaled_W, self.scaled_W)
        if self.diagonal_mass:
            return np.asarray(self.W.power(2).T @ (1.0 / self._diag)).ravel()
        G = self.delassus
        return np.asarray(G.diagonal()).ravel()


