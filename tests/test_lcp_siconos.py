"""The Siconos LCP test set through the impulse-form QP machinery (iq.solve_lcp)."""

import numpy as np
import pytest
from siconos_data import all_files, read_lcp

import impactqp as iq

FILES = all_files()


def test_data_is_present():
    assert len(FILES) == 20


def _kind(M):
    if np.abs(M - M.T).max() > 1e-12 * np.abs(M).max():
        return "nonsymmetric"
    return "psd" if np.linalg.eigvalsh(M).min() >= -1e-10 * np.abs(M).max() else "indefinite"


@pytest.mark.parametrize("path", FILES, ids=[f.name for f in FILES])
def test_siconos_problem(path):
    M, q = read_lcp(path)
    kind = _kind(M)
    if kind != "psd":
        with pytest.raises(iq.errors.NonConvexLCPError):
            iq.solve_lcp(M, q)
        return
    r = iq.solve_lcp(M, q)
    assert r.ok
    z, w = r.z, M @ r.z + q
    scale = 1 + np.linalg.norm(q)
    assert z.min() >= 0 and w.min() >= -1e-9 * scale
    assert np.abs(z * w).max() <= 1e-9 * scale * max(1, np.abs(z).max())
    # a second backend reaches a solution too (possibly another one of a solution set)
    r2 = iq.solve_lcp(M, q, backend="clarabel")
    assert r2.ok
    # w = Mz + q is unique across the solutions of a PSD LCP
    np.testing.assert_allclose(M @ r2.z, M @ r.z, atol=1e-7 * scale)


def test_block_files_match_dense_twins():
    for name in ("deudeu", "ortiz", "trivial"):
        a = read_lcp(FILES[0].parent / f"lcp_{name}.dat")
        b = read_lcp(FILES[0].parent / f"lcp_{name}_block.dat")
        np.testing.assert_array_equal(a[0], b[0])
        np.testing.assert_array_equal(a[1], b[1])


def test_singular_cps1_solution_set():
    M, q = read_lcp(FILES[0].parent / "lcp_CPS_1.dat")  # solutions: z1 + z2 = 1, z ≥ 0
    for backend in ("auto", "exact", "clarabel", "osqp"):
        z = iq.solve_lcp(M, q, backend=backend).z
        assert z.sum() == pytest.approx(1.0, abs=1e-8) and z.min() >= 0
