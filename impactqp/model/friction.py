"""Local frictional contact problems u = W r + q with Coulomb cones (placeholder: shapes only;
the full class, its certificate and its solver replace this file)."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import InputError, ShapeError


class FrictionContactProblem:
    """A local frictional contact problem u = W r + q, contact by contact (normal first).

    Parameters
    ----------
    W : ndarray or scipy.sparse matrix
        (d·m, d·m) Delassus matrix.
    q : array_like
        (d·m,) free velocity.
    mu : float or array_like
        Friction coefficient, one number or one per contact.
    contact_dim : int
        d, 2 or 3.

    Attributes
    ----------
    W : ndarray or scipy.sparse matrix
    q : ndarray
    mu : ndarray
        (m,) friction coefficients.
    contact_dim : int
    n_contacts : int
    """

    def __init__(self, W, q, mu, *, contact_dim: int = 3) -> None:
        if contact_dim not in (2, 3):
            raise InputError(f"contact_dim must be 2 or 3, got {contact_dim!r}")
        W = W if sp.issparse(W) else np.asarray(W, dtype=float)
        q = np.asarray(q, dtype=float)
        if q.ndim != 1 or q.size % contact_dim:
            raise ShapeError(f"q must be a vector of contact_dim·m entries, got shape {q.shape}")
        if W.shape != (q.size, q.size):
            raise ShapeError(f"W must be ({q.size}, {q.size}) to fit q, got {W.shape}")
        m = q.size // contact_dim
        mu = np.broadcast_to(np.asarray(mu, dtype=float), (m,)).copy() if np.ndim(mu) == 0 \
            else np.asarray(mu, dtype=float)
        if mu.shape != (m,):
            raise ShapeError(f"mu must be one number or {m} (one per contact), got {mu.shape}")
        self.W = W
        self.q = q
        self.mu = mu
        self.contact_dim = contact_dim
        self.n_contacts = m
