"""The structure of a 1-D chain of balls (docs/theory.md §5): masses validated in O(N), and M, W,
the Delassus matrix and every factorization formed only when something first asks for them.

A chain's operators (γ = Wᵀu, M⁻¹WΛ, Mu, the kinetic norm, the contact scales) are O(N)
without a matrix, and so are the isotonic backend and the chain certificate; a long chain
solved on that path never forms a matrix.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import scipy.sparse as sp

from ..base.arrays import Matrix
from ..errors import MassMatrixError, NonFiniteError, ShapeError
from ..kernels.chain import pack_chain
from .structure import ChainInfo, ImpactStructure
from .validation import check_chain_masses


def chain_directions(n_balls: int, *, left_wall: bool = False, right_wall: bool = False,
                     sparse: bool = False):
    """W of a 1-D chain: column order [left wall, gaps q₂−q₁ … q_N−q_{N−1}, right wall].

    A neighbour gap gᵢ = q_{i+1} − q_i has direction e_{i+1} − e_i; a left wall at rest
    (gap q₁ − wall) has e₁, a right wall (gap wall − q_N) has −e_N.
    """
    n = n_balls
    gaps = np.arange(n - 1)
    first = 1 if left_wall else 0
    m = first + n - 1 + (1 if right_wall else 0)
    rows = [gaps, gaps + 1]
    cols = [gaps + first, gaps + first]
    vals = [np.full(n - 1, -1.0), np.ones(n - 1)]
    for present, row, col, val in ((left_wall, 0, 0, 1.0), (right_wall, n - 1, m - 1, -1.0)):
        if present:
            rows.append(np.array([row]))
            cols.append(np.array([col]))
            vals.append(np.array([val]))
    rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    if sparse:
        return sp.csc_matrix((vals, (rows, cols)), shape=(n, m))
    W = np.zeros((n, m))
    W[rows, cols] = vals
    return W


class ChainStructure(ImpactStructure):
    """M = diag(masses) and the chain's W (docs/theory.md §5), checked in O(N) and formed lazily.

    Parameters
    ----------
    chain : ChainInfo
        Ball masses (positive, finite) and the walls.
    sparse : bool
        Whether M and W are scipy.sparse once formed (and the structure reports
        ``sparse``, which decides the preferred program form).

    Raises
    ------
    ShapeError
        Masses that are not a non-empty 1-D array.
    NonFiniteError
        A NaN or infinite mass.
    MassMatrixError
        A zero or negative mass (M would not be positive definite).
    """

    def __init__(self, chain: ChainInfo, *, sparse: bool) -> None:
        masses = chain.masses
        if masses.ndim != 1 or masses.size == 0:
            raise ShapeError(f"masses must be a non-empty 1-D array, got shape {masses.shape}")
        lo, hi = masses.min(), masses.max()
        if not (np.isfinite(lo) and np.isfinite(hi)):  # NaN propagates; ±inf is an extreme
            raise NonFiniteError("masses must be finite")
        if not lo > 0:
            raise MassMatrixError(f"masses must be positive; got "
                                  f"{masses[masses <= 0][:5].tolist()}")
        self.sparse = bool(sparse)
        self.chain = chain
        self.n = masses.size
        self.m = masses.size - 1 + chain.left_wall + chain.right_wall
        if self.m:
            check_chain_masses(lo, hi)
        self.diagonal_mass = True
        self._diag = self.mass_diagonal = masses

    @cached_property
    def M(self) -> Matrix:
        """The mass matrix diag(masses), formed on first access."""
        d = self.chain.masses
        return sp.diags(d, format="csc") if self.sparse else np.diag(d)

    @cached_property
    def W(self) -> Matrix:
        """The chain's force directions (:func:`chain_directions`), formed on first access."""
        c = self.chain
        return chain_directions(self.n, left_wall=c.left_wall, right_wall=c.right_wall,
                                sparse=self.sparse)

    @cached_property
    def chain_pack(self) -> np.ndarray:
        """Masses, their inverses and the contact scales in one array, for the compiled impact
        of a chain (:func:`!impactqp.kernels.chain.pack_chain`)."""
        return pack_chain(self.chain.masses, self.inverse_masses, self.contact_scale)

    @cached_property
    def _chol(self) -> np.ndarray:
        """Cholesky factor of a diagonal M: diag(√masses)."""
        return np.diag(np.sqrt(self.chain.masses))
