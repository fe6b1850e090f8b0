"""The impact problem: mass matrix M, contact directions W, pre-impact velocity u⁻ (§1).

The data that do not depend on u⁻ (M, W, the factorization of M, the Delassus
matrix) live in an :class:`ImpactStructure` that is validated and factorized once
and shared by every problem built with :meth:`ImpactProblem.with_u_minus`, so a
parameter sweep or a simulator pays for it only once.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import MassMatrixError, NonFiniteError, ShapeError

Matrix = Any  # numpy.ndarray or a scipy.sparse matrix/array


@dataclass(frozen=True)
class ChainInfo:
    """Marks a problem as a 1-D chain (§5): ball masses and the fixed walls, if any."""

    masses: np.ndarray
    left_wall: bool = False
    right_wall: bool = False


def _finite(name: str, values: np.ndarray) -> None:
    if not np.all(np.isfinite(values)):
        bad = np.argwhere(~np.isfinite(values))[0]
        raise NonFiniteError(f"{name} must be finite; found {values[tuple(bad)]} "
                             f"at index {tuple(bad)}")


def as_dense(A: Any) -> np.ndarray:
    """A float ndarray view of a dense or scipy.sparse matrix."""
    return A.toarray() if sp.issparse(A) else np.asarray(A, dtype=float)


def as_vector(name: str, value: Any, length: int) -> np.ndarray:
    """Return ``value`` as a finite float vector of the given length or raise InputError."""
    arr = np.asarray(value, dtype=float)
    if arr.shape != (length,):
        raise ShapeError(f"{name} must have shape ({length},), got {arr.shape}")
    _finite(name, arr)
    return arr


class ImpactStructure:
    """M and W of an impact, validated and factorized once (§1).

    Parameters
    ----------
    M : (n, n) array_like or scipy.sparse matrix
        Mass matrix, symmetric positive definite.
    W : (n, m) array_like or scipy.sparse matrix
        Generalized force directions, one column per closed contact; ``m = 0`` is allowed.
    """

    def __init__(self, M: Matrix, W: Matrix, *, chain: ChainInfo | None = None) -> None:
        self.sparse = sp.issparse(M) or sp.issparse(W)
        if self.sparse:
            M = sp.csc_matrix(M, dtype=float)
            W = sp.csc_matrix(W, dtype=float)
            m_vals, w_vals = M.data, W.data
        else:
            M = np.array(M, dtype=float)
            W = np.array(W, dtype=float)
            m_vals, w_vals = M, W
        if M.ndim != 2 or M.shape[0] != M.shape[1] or M.shape[0] == 0:
            raise ShapeError(f"M must be a non-empty square (n, n) matrix, got shape {M.shape}")
        n = M.shape[0]
        if W.ndim == 1 and W.size == 0:
            W = np.zeros((n, 0))
        if W.ndim != 2 or W.shape[0] != n:
            raise ShapeError(f"W must have shape (n, m) = ({n}, m) to match M, got {W.shape}")
        _finite("M", np.asarray(m_vals))
        _finite("W", np.asarray(w_vals))
        self.M, self.W = M, W
        self.n, self.m = n, W.shape[1]
        self.chain = chain
        self._check_symmetric()
        self._factorize()
        col_norms = np.sqrt(np.asarray(abs(W).power(2).sum(axis=0)).ravel()) if self.sparse \
            else np.linalg.norm(W, axis=0)
        if np.any(col_norms == 0):
            raise ShapeError(f"W column(s) {np.flatnonzero(col_norms == 0).tolist()} are zero: "
                             "every contact needs a non-zero force direction")

    def _check_symmetric(self) -> None:
        M = self.M
        scale = abs(M).max() if self.sparse else np.abs(M).max()
        asym = abs(M - M.T).max() if self.sparse else np.abs(M - M.T).max()
        if asym > 1e-12 * max(scale, 1e-300):
            raise MassMatrixError(f"M must be symmetric; max |M - Mᵀ| = {asym:.3g} "
                                  f"(largest entry {scale:.3g})")

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
            # LU with diagonal pivoting on a symmetric permutation: all pivots > 0 iff SPD.
            lu = spla.splu(self.M, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                           options={"SymmetricMode": True})
            pivots = lu.U.diagonal()
            if np.any(pivots <= 0) or not np.array_equal(lu.perm_r, lu.perm_c):
                raise MassMatrixError("M must be positive definite; its LDLᵀ factorization has "
                                      "a non-positive pivot")
            self._lu = lu
        else:
            self.diagonal_mass = bool(np.count_nonzero(self.M - np.diag(np.diag(self.M))) == 0)
            try:
                self._chol = sla.cholesky(self.M, lower=True)
            except np.linalg.LinAlgError:
                eig = np.linalg.eigvalsh(self.M).min()
                raise MassMatrixError("M must be positive definite; its smallest eigenvalue is "
                                      f"{eig:.3g}") from None

    # --- linear algebra in the kinetic metric -------------------------------------------
    def solve_mass(self, x: np.ndarray) -> np.ndarray:
        """Return M⁻¹x for a vector or a matrix of right-hand sides."""
        if self.sparse:
            if self.diagonal_mass:
                return x / self._diag[:, None] if x.ndim == 2 else x / self._diag
            return self._lu.solve(np.asarray(x, dtype=float))
        return sla.cho_solve((self._chol, True), x)

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

    def Wt_times(self, U: np.ndarray) -> np.ndarray:
        """Contact velocities γ = Wᵀu of a vector or of every row of U."""
        return np.asarray(self.W.T @ U.T).T

    def impulse_velocity(self, Lam: np.ndarray) -> np.ndarray:
        """Velocity jump M⁻¹WΛ of an impulse vector or of every row of Lam (§1)."""
        return np.asarray(self.Minv_W @ Lam.T).T

    @cached_property
    def cholesky_factor(self) -> np.ndarray:
        """Lower Cholesky factor L of a dense M (M = LLᵀ)."""
        if self.sparse:
            raise ValueError("the dense Cholesky factor is only kept for dense problems")
        return self._chol

    @cached_property
    def scaled_W(self) -> np.ndarray:
        """B = L⁻¹W, so that G = BᵀB (dense problems): the basis of the NNLS paths."""
        return sla.solve_triangular(self.cholesky_factor, self.W, lower=True)

    @cached_property
    def Minv_W(self) -> Matrix:
        """M⁻¹W (sparse when M is diagonal and W sparse, dense otherwise)."""
        if self.sparse and self.diagonal_mass:
            return sp.csc_matrix(sp.diags(1.0 / self._diag) @ self.W)
        return self.solve_mass(as_dense(self.W))

    @cached_property
    def delassus(self) -> Matrix:
        """Delassus matrix G = WᵀM⁻¹W (§1), symmetric positive semidefinite."""
        if self.sparse and self.diagonal_mass:
            G = sp.csc_matrix(self.W.T @ self.Minv_W)
            return (G + G.T) * 0.5
        if not self.sparse:
            B = self.scaled_W
            return B.T @ B
        G = np.asarray(self.W.T @ self.Minv_W)
        return 0.5 * (G + G.T)

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
        """sᵢ = sqrt(Gᵢᵢ): |γᵢ| ≤ sᵢ‖u‖ (the unit of contact velocities in certificates)."""
        return np.sqrt(self.delassus_diagonal)

    @cached_property
    def kernel(self):
        """The prepared active-set kernel of G (dense problems with few contacts)."""
        from .kernel import ActiveSetKernel

        return ActiveSetKernel(as_dense(self.delassus))

    @cached_property
    def delassus_diagonal(self) -> np.ndarray:
        """Diagonal of G: the squared M⁻¹-length of each contact direction."""
        G = self.delassus
        return np.asarray(G.diagonal()).ravel() if sp.issparse(G) else np.diag(G).copy()


class ImpactProblem:
    """One frictionless impact: M, W and the pre-impact velocity u⁻ (§1).

    Parameters
    ----------
    M : (n, n) array_like or scipy.sparse matrix
        Mass matrix, symmetric positive definite (the kinetic metric).
    W : (n, m) array_like or scipy.sparse matrix
        Generalized force directions of the closed contacts; ``m = 0`` means no contact.
    u_minus : (n,) array_like
        Pre-impact generalized velocity. Kinematically inconsistent values (a closed contact
        already separating, γ⁻ᵢ > 0) are legal.

    Raises
    ------
    ShapeError, NonFiniteError, MassMatrixError
        On malformed input; all are ``ValueError`` subclasses.
    """

    def __init__(self, M: Matrix, W: Matrix, u_minus: Any, *,
                 structure: ImpactStructure | None = None) -> None:
        self.structure = structure if structure is not None else ImpactStructure(M, W)
        self.u_minus = as_vector("u_minus", u_minus, self.structure.n)
        self.u_minus.setflags(write=False)

    @classmethod
    def from_structure(cls, structure: ImpactStructure, u_minus: Any) -> ImpactProblem:
        """A problem on an already validated structure (no re-factorization)."""
        return cls(None, None, u_minus, structure=structure)

    def with_u_minus(self, u_minus: Any) -> ImpactProblem:
        """The same M and W (sharing factorizations) with another pre-impact velocity."""
        return ImpactProblem.from_structure(self.structure, u_minus)

    # --- data ------------------------------------------------------------------------
    M = property(lambda self: self.structure.M, doc="Mass matrix (n, n).")
    W = property(lambda self: self.structure.W, doc="Force directions (n, m).")
    n_dof = property(lambda self: self.structure.n, doc="Number of degrees of freedom n.")
    n_contacts = property(lambda self: self.structure.m, doc="Number of closed contacts m.")
    chain = property(lambda self: self.structure.chain, doc="ChainInfo for 1-D chains, else None.")
    delassus = property(lambda self: self.structure.delassus, doc="Delassus matrix G = WᵀM⁻¹W.")

    @cached_property
    def gamma_minus(self) -> np.ndarray:
        """Pre-impact contact velocities γ⁻ = Wᵀu⁻ (γ > 0 separates)."""
        return self.structure.Wt_times(self.u_minus)

    def norm(self, u: np.ndarray) -> float:
        """Kinetic norm ‖u‖ = sqrt(uᵀMu)."""
        return float(np.sqrt(max(float(u @ self.structure.mass_rows(u)), 0.0)))

    def inner(self, a: np.ndarray, b: np.ndarray) -> float:
        """Kinetic inner product ⟨a, b⟩ = aᵀMb."""
        return float(a @ self.structure.mass_rows(b))

    def kinetic_energy(self, u: np.ndarray | None = None) -> float:
        """T = ½uᵀMu (of u⁻ when u is omitted)."""
        u = self.u_minus if u is None else u
        return 0.5 * self.norm(u) ** 2

    @property
    def velocity_scale(self) -> float:
        """‖u⁻‖, the natural velocity unit of certificates (1 when u⁻ = 0)."""
        s = self.norm(self.u_minus)
        return s if s > 0 else 1.0

    @cached_property
    def moreau_split(self) -> tuple[np.ndarray, np.ndarray]:
        """(z, z⊥): z = prox_{T_C}(u⁻) in the metric M and z⊥ = u⁻ − z (§1, §3).

        Computed by the exact Moreau ε = 0 solve and cached.
        """
        from .laws import moreau  # local import: laws depend on this module

        r = moreau(self, eps=0.0)
        return r.z, r.z_perp

    def admissible_set(self):
        """The admissible set S of this impact (§2); see :class:`impactqp.AdmissibleSet`."""
        from .admissible import AdmissibleSet

        return AdmissibleSet(self)

    def __repr__(self) -> str:
        kind = "sparse" if self.structure.sparse else "dense"
        return f"ImpactProblem(n_dof={self.n_dof}, n_contacts={self.n_contacts}, {kind})"
