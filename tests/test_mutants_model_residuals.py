"""The certificate's residuals as the model assembles them (impactqp/model/residuals.py) —
dense, sparse, chain, one impact or rows, any velocity scale — against the numpy reference
written from docs/theory.md §8 in tests/test_mutants_kernels.py; written to kill the mutants
benchmarks/mutation.py makes of the module."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from test_mutants_kernels import residuals_reference

import impactqp as iq
from impactqp.model.residuals import (
    impact_residuals,
    law_residuals,
    normalized_rows,
    restitution_matrix,
)

NAMES = ("momentum", "impulse_sign", "law_feasibility", "complementarity", "energy_balance",
         "duality_gap")


def _random(seed: int, n: int = 5, m: int = 3):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    W = rng.normal(size=(n, m))
    return rng, M, W


def _as_array(res: dict, moreau: bool) -> np.ndarray:
    return np.array([res[k] for k in NAMES[:6 if moreau else 4]], dtype=float)


@pytest.mark.parametrize("sparse", [False, True])
@pytest.mark.parametrize("law", ["moreau", "scalar", "vector", "matrix"])
def test_law_residuals_are_the_formulas(sparse: bool, law: str) -> None:
    rng, M, W = _random(3)
    n, m = W.shape
    um = rng.normal(size=n)
    p = iq.ImpactProblem(sp.csc_matrix(M) if sparse else M, sp.csc_matrix(W) if sparse else W,
                         um)
    st = p.structure
    assert st.sparse == sparse
    E = {"moreau": 0.4, "scalar": 0.7, "vector": rng.uniform(0, 1, m),
         "matrix": rng.uniform(0, 0.5, (m, m))}[law]
    moreau = law == "moreau"
    Emat = restitution_matrix(E, m)
    for scale in (1.0, 1e-75, 1e75):
        up, lam = rng.normal(size=n), rng.normal(size=m)
        res = law_residuals(st, scale * um, scale * up, scale * lam, E,
                            eps=0.4 if moreau else None)
        assert set(res) == set(NAMES[:6 if moreau else 4])
        ref = residuals_reference(M, W, um, up, lam, Emat, 0.4, moreau)
        np.testing.assert_allclose(_as_array(res, moreau), ref[:6 if moreau else 4],
                                   rtol=1e-9, atol=1e-15)


@pytest.mark.parametrize("sparse", [False, True])
def test_rows_are_judged_one_by_one(sparse: bool) -> None:
    rng, M, W = _random(4)
    n, m = W.shape
    p = iq.ImpactProblem(sp.csc_matrix(M) if sparse else M, sp.csc_matrix(W) if sparse else W,
                         rng.normal(size=n))
    scales = np.array([1.0, 1e-80, 1e80, 3.0])
    Um = rng.normal(size=(4, n)) * scales[:, None]
    Up = rng.normal(size=(4, n)) * scales[:, None]
    Lam = rng.normal(size=(4, m)) * scales[:, None]
    Um[3] = 0.0  # at rest: measured against the answer's own size
    rows = law_residuals(p.structure, Um, Up, Lam, 0.5, eps=0.5)
    for r in range(4):
        one = law_residuals(p.structure, Um[r], Up[r], Lam[r], 0.5, eps=0.5)
        for k in NAMES:
            assert rows[k][r] == pytest.approx(one[k], rel=1e-9, abs=1e-15)
        if r < 3:
            ref = residuals_reference(M, W, Um[r] / scales[r], Up[r] / scales[r],
                                      Lam[r] / scales[r], 0.5 * np.eye(m), 0.5, True)
            np.testing.assert_allclose([rows[k][r] for k in NAMES], ref, rtol=1e-9,
                                       atol=1e-15)
    # u⁻ = 0: inputs divided by the largest entry of u⁺ and Λ, V = max(‖u⁺‖, 1) there
    c = max(np.abs(Up[3]).max(), np.abs(Lam[3]).max())
    ref = residuals_reference(M, W, np.zeros(n), Up[3] / c, Lam[3] / c, 0.5 * np.eye(m), 0.5,
                              True)
    np.testing.assert_allclose([rows[k][3] for k in NAMES[:4]], ref[:4], rtol=1e-9,
                               atol=1e-15)


@pytest.mark.parametrize("walls", [(False, False), (True, True), (True, False)])
def test_chain_residuals_are_the_formulas(walls: tuple[bool, bool]) -> None:
    rng = np.random.default_rng(6)
    masses = rng.uniform(0.5, 2.0, 5)
    um = rng.normal(size=5)
    p = iq.chain(masses, um, left_wall=walls[0], right_wall=walls[1])
    st = p.structure
    assert st.chain is not None
    M, W = np.diag(masses), np.asarray(p.W.toarray() if sp.issparse(p.W) else p.W)
    m = W.shape[1]
    up, lam = rng.normal(size=5), rng.normal(size=m)
    for eps in (None, 0.3):
        res = law_residuals(st, um, up, lam, 0.3, eps=eps)
        ref = residuals_reference(M, W, um, up, lam, 0.3 * np.eye(m), 0.3, eps is not None)
        np.testing.assert_allclose(_as_array(res, eps is not None), ref[:len(res)],
                                   rtol=1e-9, atol=1e-15)
    bad = law_residuals(st, um, up, lam[:-1], 0.3, eps=0.3)  # a wrong shape fails
    assert len(bad) == 6 and all(np.isnan(v) for v in bad.values())


def test_normalized_rows() -> None:
    a = np.array([[1.0, -2.0], [0.0, 0.0], [3e70, 1.0], [0.0, 0.0]])
    b = np.array([[4.0, 0.0], [0.0, -5.0], [1.0, 1.0], [0.0, 0.0]])
    na, nb = normalized_rows(a, b)
    np.testing.assert_array_equal(na[0], [0.5, -1.0])  # rows are divided by their own scale
    np.testing.assert_array_equal(nb[1], [0.0, -1.0])  # u⁻ = 0: by the others' largest entry
    np.testing.assert_allclose(na[2], [1.0, 1.0 / 3e70])
    np.testing.assert_array_equal(nb[3], [0.0, 0.0])  # all zero: by 1
    same = normalized_rows(a[:1], b[:1])  # in range: left as they are
    assert same[0] is a[:1] or np.array_equal(same[0], a[:1])
    one = normalized_rows(np.array([0.0, 0.0]), np.array([0.0, 2e-70]))
    np.testing.assert_array_equal(one[1], [0.0, 1.0])


def test_restitution_matrix() -> None:
    np.testing.assert_array_equal(restitution_matrix(0.5, 2), [[0.5, 0.0], [0.0, 0.5]])
    np.testing.assert_array_equal(restitution_matrix([0.1, 0.2], 2), [[0.1, 0.0], [0.0, 0.2]])
    E = np.array([[0.1, 0.2], [0.3, 0.4]])
    np.testing.assert_array_equal(restitution_matrix(E, 2), E)


@pytest.mark.parametrize("sparse", [False, True])
def test_impact_residuals_are_the_formulas(sparse: bool) -> None:
    # the residuals every law shares (the sector, reflection, LZB and Coulomb certificates
    # read them): the momentum and the impulse sign, one impact and rows, u⁻ = 0 included
    rng, M, W = _random(8)
    n, m = W.shape
    p = iq.ImpactProblem(sp.csc_matrix(M) if sparse else M, sp.csc_matrix(W) if sparse else W,
                         rng.normal(size=n))
    Um, Up, Lam = rng.normal(size=(3, n)), rng.normal(size=(3, n)), rng.normal(size=(3, m))
    Um[2] = 0.0
    Um, Up, Lam = normalized_rows(Um, Up, Lam)
    V, rows = impact_residuals(p.structure, Um, Up, Lam)
    for r in range(3):
        ref = residuals_reference(M, W, Um[r], Up[r], Lam[r], np.eye(m), 0.0, False)
        np.testing.assert_allclose([rows["momentum"][r], rows["impulse_sign"][r]], ref[:2],
                                   rtol=1e-9, atol=1e-15)
        Vr, one = impact_residuals(p.structure, Um[r], Up[r], Lam[r])
        assert float(Vr) == pytest.approx(V[r], rel=1e-12)
        assert float(one["momentum"]) == pytest.approx(rows["momentum"][r], rel=1e-12)
    assert V[2] == pytest.approx(max(np.sqrt(Up[2] @ M @ Up[2]), 1.0), rel=1e-12)
    q = iq.ImpactProblem(np.eye(2), np.zeros((2, 0)), np.array([1.0, 0.0]))  # no contacts
    _, none = impact_residuals(q.structure, np.array([1.0, 0.0]), np.array([0.0, 1.0]),
                               np.zeros(0))
    assert none["impulse_sign"] == 0.0 and none["momentum"] == pytest.approx(np.sqrt(2.0))
