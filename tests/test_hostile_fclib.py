"""FCLib and Siconos files whose numbers are well-formed but physically impossible: a global
problem's M that is not positive definite (negative or indefinite masses) and a Delassus
matrix W with a negative diagonal entry are refused by name, never reduced and "certified";
a singular M is reported without the sparse solver's source locations."""

from __future__ import annotations

import shutil
import time
from pathlib import Path

import h5py  # a dependency of impactqp
import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from impactqp.cli.main import main
from impactqp.errors import ProblemFileError
from impactqp.io.siconos_text import write_siconos_text

DATA = Path(__file__).resolve().parent / "data" / "fclib"
GLOBAL = DATA / "LMGC_GlobalFrictionContactProblem00046.hdf5"
LOCAL = DATA / "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5"


def _edited(src: Path, tmp_path: Path, dataset: str, edit) -> Path:
    dst = tmp_path / f"edited-{src.name}"
    shutil.copy(src, dst)
    with h5py.File(dst, "r+") as f:
        data = f[dataset]
        data[...] = edit(data[...].copy())
    return dst


def _negate_first(x: np.ndarray) -> np.ndarray:
    x[0] = -x[0]
    return x


@pytest.mark.parametrize("edit", [np.negative, _negate_first], ids=["negative", "indefinite"])
def test_a_global_mass_matrix_that_is_not_positive_definite_is_refused(edit, tmp_path):
    # negated, W = Hᵀ M⁻¹ H is negative definite and was "certified" with error 0
    path = _edited(GLOBAL, tmp_path, "fclib_global/M/x", edit)
    with pytest.raises(ProblemFileError, match=r"fclib_global/M.*positive definite") as info:
        iq.load_fclib(path)
    assert str(path) in str(info.value)


def test_the_shipped_global_problems_still_load():
    for name in ("LMGC_GlobalFrictionContactProblem00046.hdf5", "Box_Stacks-i0122-82-5.hdf5"):
        assert iq.load_fclib(DATA / name).n_contacts > 0


def test_a_singular_mass_matrix_is_named_without_solver_internals(tmp_path):
    # nz = 5: M read as a triplet of its first five entries, singular
    path = _edited(GLOBAL, tmp_path, "fclib_global/M/nz", lambda x: np.full_like(x, 5))
    with pytest.raises(ProblemFileError, match="fclib_global/M") as info:
        iq.load_fclib(path)
    assert ".c" not in str(info.value) and "SuperLU" not in str(info.value)


def test_a_negative_diagonal_of_w_is_refused_in_hdf5(tmp_path):
    path = _edited(LOCAL, tmp_path, "fclib_local/W/x", np.negative)
    with pytest.raises(ProblemFileError, match=r"fclib_local/W.*diagonal"):
        iq.load_fclib(path)


@pytest.mark.parametrize("entry", [0, 1], ids=["normal", "tangent"])
def test_a_negative_diagonal_of_w_is_refused_in_siconos_text(entry, tmp_path, capsys):
    W = np.array([[2.0, 0.1, 0.0], [0.1, 1.0, 0.0], [0.0, 0.0, 1.0]])
    W[entry, entry] = -W[entry, entry]
    path = write_siconos_text(iq.FrictionContactProblem(W, [-1.0, 0.5, 0.0], 0.3),
                              tmp_path / "bad.dat")
    with pytest.raises(ProblemFileError, match=r"bad\.dat.*W.*diagonal"):
        iq.load_fclib(path)
    assert main(["fclib", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "diagonal" in err[0] and "Traceback" not in err[0]


def _global_file(path: Path, M: sp.spmatrix, H: sp.spmatrix, f, w, mu) -> Path:
    """A global FCLib file (triplet storage, gzip-compressed datasets)."""
    with h5py.File(path, "w") as h:
        g = h.create_group("fclib_global")
        for name, A in (("M", sp.coo_matrix(M)), ("H", sp.coo_matrix(H))):
            group = g.create_group(name)
            for key, value in (("m", A.shape[0]), ("n", A.shape[1]), ("nz", A.nnz),
                               ("nzmax", A.nnz)):
                group[key] = np.array([value], dtype=np.int32)
            for key, value in (("i", A.row.astype(np.int32)), ("p", A.col.astype(np.int32)),
                               ("x", A.data)):
                group.create_dataset(key, data=value, compression="gzip")
        g["spacedim"] = np.array([3], dtype=np.int32)
        vectors = g.create_group("vectors")
        for key, value in (("f", f), ("w", w), ("mu", mu)):
            vectors.create_dataset(key, data=np.asarray(value, dtype=float), compression="gzip")
    return path


def test_a_small_global_file_with_a_large_reduction_loads_in_seconds(tmp_path):
    """60000 degrees of freedom with a diagonal M and 6000 contacts: a 0.3 MB file whose
    reduction by dense blocks of M⁻¹H took 155 s and 0.9 GB; M⁻¹ is sparse here (so it is
    for every block-diagonal M of rigid bodies), and W = HᵀM⁻¹H is formed sparse."""
    n, m = 60_000, 6_000
    rng = np.random.default_rng(0)
    masses = rng.uniform(0.5, 2.0, n)
    columns = np.arange(3 * m)
    H = sp.csc_matrix((rng.standard_normal(3 * m), (columns * 7 % n, columns)), shape=(n, 3 * m))
    f, w = rng.standard_normal(n), rng.standard_normal(3 * m)
    path = _global_file(tmp_path / "big.hdf5", sp.diags(masses), H, f, w, np.full(m, 0.3))
    start = time.process_time()
    problem = iq.load_fclib(path)
    assert time.process_time() - start < 5.0
    expected = sp.csc_matrix(H.T @ sp.diags(1.0 / masses) @ H)  # by hand, sparse
    assert abs(problem.W - expected).max() <= 1e-15 * abs(expected).max()
    assert problem.W.nnz == expected.nnz
    np.testing.assert_allclose(problem.q, H.T @ (f / masses) + w, rtol=1e-13, atol=1e-13)


def test_block_diagonal_mass_is_reduced_exactly(tmp_path):
    """Rigid bodies: M of 6×6 blocks (one dense symmetric positive definite block per body),
    reduced sparse; the same W as the dense reduction by hand, and the shipped LMGC-00046
    (two blocks of 81) agrees with its own by-hand reduction."""
    rng = np.random.default_rng(1)
    blocks = []
    for _ in range(50):
        A = rng.standard_normal((6, 6))
        blocks.append(A @ A.T + 6 * np.eye(6))
    M = sp.block_diag(blocks, format="csc")
    H = sp.random(300, 30, density=0.05, random_state=2, format="csc")
    H = H + sp.csc_matrix((np.ones(30), (np.arange(30) * 9, np.arange(30))), shape=(300, 30))
    f, w = rng.standard_normal(300), rng.standard_normal(30)
    problem = iq.load_fclib(_global_file(tmp_path / "rigid.hdf5", M, H, f, w, np.full(10, 0.5)))
    Md = M.toarray()
    expected = H.T.toarray() @ np.linalg.solve(Md, H.toarray())
    np.testing.assert_allclose(problem.W.toarray(), expected, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(problem.q, H.T @ np.linalg.solve(Md, f) + w, rtol=1e-10, atol=1e-12)


def test_a_reduction_beyond_the_work_limit_is_refused_before_it_starts(tmp_path, monkeypatch):
    """A mass matrix of one large block (a deformable body) is reduced by dense blocks of
    M⁻¹H, n·(3m + 1) entries of work: over the limit the file is refused by name at once."""
    n, m = 3_000, 400
    main_diagonal, off = np.full(n, 4.0), np.full(n - 1, -1.0)
    M = sp.diags([off, main_diagonal, off], [-1, 0, 1], format="csc")  # one connected block
    columns = np.arange(3 * m)
    H = sp.csc_matrix((np.ones(3 * m), (columns, columns)), shape=(n, 3 * m))
    path = _global_file(tmp_path / "chain.hdf5", M, H, np.zeros(n), -np.ones(3 * m),
                        np.full(m, 0.3))
    assert iq.load_fclib(path).n_contacts == m  # 3.6e6 entries: within the limit
    monkeypatch.setattr("impactqp.io.fclib_reduce.REDUCTION_WORK", 1e6)
    start = time.process_time()
    with pytest.raises(ProblemFileError, match=r"chain\.hdf5.*fclib_global/M.*work"):
        iq.load_fclib(path)
    assert time.process_time() - start < 1.0


def test_a_reduced_w_too_large_to_store_is_refused_before_it_is_formed(tmp_path):
    """One unknown met by 10⁴ contacts: W = Hᵀ M⁻¹ H would be dense, 9·10⁸ entries (7 GB)."""
    m = 10_000
    H = sp.csc_matrix(np.ones((1, 3 * m)))
    path = _global_file(tmp_path / "star.hdf5", sp.identity(1), H, [0.0], np.ones(3 * m),
                        np.full(m, 0.3))
    start = time.process_time()
    with pytest.raises(ProblemFileError, match=r"star\.hdf5.*fclib_global/M.*entries"):
        iq.load_fclib(path)
    assert time.process_time() - start < 2.0
