"""Newton's Jacobian J = A + λI + B W assembled from W's contact blocks
(:class:`impactqp.qp.friction.data.ContactBlocks`, docs/theory.md §15) against the same
matrix formed densely, block by block."""

import numpy as np
import pytest
import scipy.linalg as sla
import scipy.sparse as sp

from impactqp.qp.friction.data import ContactBlocks


@pytest.mark.parametrize("d", [1, 2, 3])
def test_jacobian_matches_dense_formula(d: int) -> None:
    rng = np.random.default_rng(d)
    m = 7
    n = d * m
    W = rng.standard_normal((n, n)) * (rng.random((n, n)) < 0.3)
    W[2 * d:3 * d, 2 * d:3 * d] = 0.0  # a contact whose diagonal block is not stored
    A = rng.standard_normal((m, d, d))
    B = rng.standard_normal((m, d, d))
    shift = 0.37
    expected = sla.block_diag(*A) + shift * np.eye(n) + sla.block_diag(*B) @ W
    blocks = ContactBlocks.of(sp.csr_matrix(W), d)
    J = blocks.jacobian(A, B, shift)
    assert isinstance(J, sp.csc_matrix)
    np.testing.assert_allclose(J.toarray(), expected, rtol=0, atol=1e-12)
    assert blocks.diagonal.size == m  # every contact's diagonal block is stored


def test_jacobian_of_an_empty_W_is_A_and_the_shift() -> None:
    d, m = 3, 4
    A = np.tile(np.eye(d), (m, 1, 1)) * 2.0
    B = np.ones((m, d, d))
    J = ContactBlocks.of(sp.csr_matrix((d * m, d * m)), d).jacobian(A, B, 0.5)
    np.testing.assert_array_equal(J.toarray(), 2.5 * np.eye(d * m))
