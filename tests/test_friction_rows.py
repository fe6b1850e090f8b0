"""W by contacts (kernels/friction_rows.py) and a planar contact's cases in scalars
(kernels/friction_planar.py), as the projected Gauss–Seidel uses them (docs/theory.md §15)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from impactqp.kernels.friction import natural_map, nsgs_rows
from impactqp.kernels.friction_planar import planar_contact
from impactqp.kernels.friction_rows import contact_rows


def _contacts(m: int, d: int, rng: np.random.Generator) -> sp.coo_matrix:
    """A symmetric positive definite W of m contacts, each of the first m − 1 touching a few
    others, the last touching none, with its first five entries given twice (in halves, as a
    COO or CSR may hold duplicates)."""
    H = sp.random((m - 1) * d, 2 * m * d, density=0.08, random_state=rng)
    W = sp.block_diag([H @ H.T + sp.eye((m - 1) * d), 2.0 * np.eye(d)]).tocoo()
    row = np.concatenate([W.row, W.row[:5]])
    col = np.concatenate([W.col, W.col[:5]])
    val = np.concatenate([W.data, W.data[:5]])
    val[:5] *= 0.5
    val[-5:] *= 0.5
    return sp.coo_matrix((val, (row, col)), shape=W.shape)


@pytest.mark.parametrize("d", [2, 3])
def test_contact_rows_hold_W_and_its_product(d: int) -> None:
    rng = np.random.default_rng(3 + d)
    m = 12
    coo = _contacts(m, d, rng)
    indptr = np.zeros(m * d + 1, dtype=np.int32)
    order = np.lexsort((coo.col, coo.row))
    np.add.at(indptr, coo.row + 1, 1)
    indptr = np.cumsum(indptr).astype(np.int32)
    indices = coo.col[order].astype(np.int32)
    data = coo.data[order].astype(float)
    dense = np.zeros((m * d, m * d))
    np.add.at(dense, (coo.row, coo.col), coo.data)  # duplicates summed
    rows = contact_rows(indptr, indices, data, m, d)
    rebuilt = np.zeros_like(dense)
    for c in range(m):
        rebuilt[c * d:(c + 1) * d, c * d:(c + 1) * d] = rows.diagonal[c]
        for t in range(rows.start[c], rows.start[c + 1]):
            j = rows.other[t]
            assert j != c
            rebuilt[c * d:(c + 1) * d, j * d:(j + 1) * d] += rows.block[t]
    assert np.array_equal(rebuilt, dense)
    assert rows.start[m] == rows.start[m - 1]  # the lone contact has no block
    assert np.unique(rows.other[rows.start[0]:rows.start[1]]).size == rows.start[1]


@pytest.mark.parametrize("d", [2, 3])
def test_sweeps_by_contacts_solve_the_problem(d: int) -> None:
    """NSGS on W by contacts ends with ‖F‖ ≤ tol·‖q‖, ‖F‖ recomputed here from a dense
    product, and the same answer from W given dense (its nonzero entries)."""
    rng = np.random.default_rng(11 + d)
    m = 20
    W = _contacts(m, d, rng).tocsr()
    q = rng.normal(size=m * d)
    mu = rng.uniform(0.1, 0.9, size=m)
    r = np.zeros(m * d)
    sweeps, err = nsgs_rows(W.indptr, W.indices, W.data, q, mu, d, r, 1e-10, 5000, 10)
    assert sweeps < 5000
    dense = W.toarray()
    F = natural_map(r, dense @ r + q, mu, d)
    assert np.linalg.norm(F) <= 1e-10 * np.linalg.norm(q) * (1 + 1e-9)
    assert err == pytest.approx(np.linalg.norm(F) / np.linalg.norm(q), rel=1e-6, abs=1e-16)


def test_planar_contact_cases_solve_the_local_problem() -> None:
    """Each case planar_contact reports solves u = W r + b, K_μ ∋ r ⟂ ũ ∈ K*_μ: its natural
    map, computed by the one definition, vanishes to round-off; apart, sticking and both
    sliding directions all occur; no case holds only where none can (checked by a fine
    search for a solution of the natural map on the cone's rays)."""
    rng = np.random.default_rng(7)
    seen = set()
    for _ in range(4000):
        A = rng.normal(size=(2, 2))
        Wc = A @ A.T + 0.05 * np.eye(2) + 0.3 * rng.normal(size=(2, 2)) * rng.integers(0, 2)
        b = rng.normal(size=2)
        mu = float(rng.uniform(0.0, 1.2))
        ok, rn, rt = planar_contact(Wc[0, 0], Wc[0, 1], Wc[1, 0], Wc[1, 1], b[0], b[1], mu)
        if not ok:
            continue
        r = np.array([rn, rt])
        u = Wc @ r + b
        F = natural_map(r, u, np.array([mu]), 2)
        scale = 1.0 + np.abs(b).max() + np.abs(Wc).max() * np.abs(r).max()
        assert np.abs(F).max() <= 1e-12 * scale
        if b[0] >= 0:
            seen.add("apart")
        elif abs(u[0]) <= 1e-12 * scale and abs(u[1]) <= 1e-12 * scale:
            seen.add("stick")
        else:
            seen.add("slide +" if rt > 0 else "slide -")
    assert seen == {"apart", "stick", "slide +", "slide -"}
