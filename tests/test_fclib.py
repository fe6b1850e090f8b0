"""FCLib files: the shipped Siconos problems load with their sizes and μ, local problems
round-trip bit for bit, a global problem reduces to the hand-computed W = Hᵀ M⁻¹ H,
q = Hᵀ M⁻¹ f + w in every sparse storage, and hostile files are refused by name."""

from __future__ import annotations

import os
from pathlib import Path

import h5py  # a dependency of impactqp
import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from impactqp.errors import InputError, ProblemFileError
from impactqp.io.fclib import load_fclib, save_fclib
from impactqp.model.friction import FrictionContactProblem

DATA = Path(__file__).resolve().parent / "data" / "fclib"

# file: (contacts, the distinct μ, entries of W)
SHIPPED = {
    "Box_Stacks-i0122-82-5.hdf5": (82, [0.3], 2016),
    "Capsules-i125-1213.hdf5": (286, [0.7], 11772),
    "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5": (60, [0.3, 0.5], 9576),
    "LMGC_GlobalFrictionContactProblem00046.hdf5": (9, [0.3], 729),
    "spheres-in-a-box-98-i10000-256-10.hdf5": (256, [0.1], 17424),
}


def test_every_shipped_file_is_listed() -> None:
    assert {p.name for p in DATA.glob("*.hdf5")} == set(SHIPPED)
    readme = (DATA / "README.md").read_text(encoding="utf-8")
    assert all(name in readme for name in SHIPPED) and "Apache-2.0" in readme


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_file_loads(name: str) -> None:
    contacts, mus, nnz = SHIPPED[name]
    problem = load_fclib(DATA / name)
    assert isinstance(problem, FrictionContactProblem)
    assert problem.contact_dim == 3 and problem.n_contacts == contacts
    assert problem.W.shape == (3 * contacts, 3 * contacts) and problem.q.shape == (3 * contacts,)
    assert sp.issparse(problem.W) and problem.W.nnz == nnz
    assert np.all(np.isfinite(problem.W.data)) and np.all(np.isfinite(problem.q))
    np.testing.assert_array_equal(np.unique(problem.mu), mus)


def test_global_reduction_has_fclib_sign() -> None:
    """M v = H r + f: the boxes of Box_Stacks press on every support under gravity, so every
    free normal velocity Hᵀ M⁻¹ f + w is negative (with −f every one would be separating)."""
    problem = load_fclib(DATA / "Box_Stacks-i0122-82-5.hdf5")
    assert np.all(problem.q[::3] < 0)


def test_local_file_is_read_as_stored() -> None:
    """Capsules stores W in compressed rows: entry (row, column) as written there."""
    problem = load_fclib(DATA / "Capsules-i125-1213.hdf5")
    with h5py.File(DATA / "Capsules-i125-1213.hdf5") as f:
        g = f["fclib_local/W"]
        assert g["nz"][0] == -2
        p, i, x = g["p"][()], g["i"][()], g["x"][()]
        q = f["fclib_local/vectors/q"][()]
    row = 5
    dense_row = problem.W.toarray()[row]
    np.testing.assert_array_equal(dense_row[i[p[row]:p[row + 1]]], x[p[row]:p[row + 1]])
    assert np.count_nonzero(dense_row) == p[row + 1] - p[row]
    np.testing.assert_array_equal(problem.q, q)


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_round_trip(name: str, tmp_path: Path) -> None:
    problem = load_fclib(DATA / name)
    path = save_fclib(problem, tmp_path / "p.hdf5")
    again = load_fclib(path)
    assert (again.W != problem.W).nnz == 0
    np.testing.assert_array_equal(again.q, problem.q)
    np.testing.assert_array_equal(again.mu, problem.mu)
    assert again.contact_dim == problem.contact_dim


def test_round_trip_dense_planar(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    A = rng.standard_normal((6, 6))
    problem = FrictionContactProblem(A @ A.T, rng.standard_normal(6), [0.2, 0.4, 0.6],
                                     contact_dim=2)
    again = load_fclib(save_fclib(problem, tmp_path / "planar.hdf5"))
    assert again.contact_dim == 2 and again.n_contacts == 3
    np.testing.assert_array_equal(again.W.toarray(), problem.W)
    np.testing.assert_array_equal(again.q, problem.q)
    np.testing.assert_array_equal(again.mu, problem.mu)
    with h5py.File(tmp_path / "planar.hdf5") as f:  # the layout FCLib and Siconos read
        assert f["fclib_local/spacedim"][()].tolist() == [2]
        assert f["fclib_local/W/nz"][()].tolist() == [-1]
        assert f["fclib_local/W/p"].dtype == np.int32


def _write_matrix(group, A: np.ndarray, storage: str) -> None:
    """A in FCLib's CSparse layout: "csc" (nz = −1), "csr" (nz = −2) or "triplet"."""
    S = sp.coo_matrix(A)
    if storage == "triplet":
        p, i, x, nz = S.col, S.row, S.data, S.nnz
    elif storage == "csc":
        C = sp.csc_matrix(A)
        p, i, x, nz = C.indptr, C.indices, C.data, -1
    else:
        C = sp.csr_matrix(A)
        p, i, x, nz = C.indptr, C.indices, C.data, -2
    for key, value in (("nzmax", len(x)), ("m", A.shape[0]), ("n", A.shape[1]), ("nz", nz)):
        group[key] = np.array([value], dtype=np.int32)
    group["p"] = np.asarray(p, dtype=np.int32)
    group["i"] = np.asarray(i, dtype=np.int32)
    group["x"] = np.asarray(x, dtype=float)


def _tiny_global():
    """Two 3-D contacts on a body with 4 degrees of freedom, M non-diagonal."""
    M = np.array([[4.0, 1.0, 0.0, 0.0], [1.0, 3.0, 0.5, 0.0], [0.0, 0.5, 2.0, 0.0],
                  [0.0, 0.0, 0.0, 1.5]])
    H = np.array([[1.0, 0.0, 0.2, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 1.0, 0.0, 0.3],
                  [0.5, 0.0, 1.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 0.7, 0.0, 1.0]])
    f = np.array([0.1, -0.4, 0.3, -0.2])
    w = np.array([0.01, 0.0, 0.0, -0.02, 0.0, 0.0])
    return M, H, f, w, np.array([0.3, 0.6])


def _write_global(path: Path, storage: str = "triplet", **extra) -> None:
    M, H, f, w, mu = _tiny_global()
    with h5py.File(path, "w") as h:
        root = h.create_group("fclib_global")
        root["spacedim"] = np.array([3], dtype=np.int32)
        _write_matrix(root.create_group("M"), M, storage)
        _write_matrix(root.create_group("H"), H, storage)
        root["vectors/f"], root["vectors/w"], root["vectors/mu"] = f, w, mu
        for name, value in extra.items():
            root[name] = value


@pytest.mark.parametrize("storage", ["triplet", "csc", "csr"])
def test_global_reduction_by_hand(storage: str, tmp_path: Path) -> None:
    M, H, f, w, mu = _tiny_global()
    _write_global(tmp_path / "g.hdf5", storage)
    problem = load_fclib(tmp_path / "g.hdf5")
    W = H.T @ np.linalg.solve(M, H)
    q = H.T @ np.linalg.solve(M, f) + w
    np.testing.assert_allclose(problem.W.toarray(), W, rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(problem.q, q, rtol=1e-13, atol=1e-15)
    np.testing.assert_array_equal(problem.mu, mu)
    assert problem.n_contacts == 2 and problem.contact_dim == 3


def test_triplet_duplicates_add_up(tmp_path: Path) -> None:
    """CSparse triplets sum repeated entries: M split into two halves reads as M."""
    M, H, f, w, mu = _tiny_global()
    _write_global(tmp_path / "g.hdf5")
    with h5py.File(tmp_path / "g.hdf5", "r+") as h:
        g = h["fclib_global/M"]
        p, i, x = g["p"][()], g["i"][()], g["x"][()]
        for key, value in (("p", np.r_[p, p]), ("i", np.r_[i, i]), ("x", np.r_[x, x] / 2)):
            del g[key]
            g[key] = value
        g["nz"][0] = g["nzmax"][0] = 2 * len(x)
    W = H.T @ np.linalg.solve(M, H)
    np.testing.assert_allclose(load_fclib(tmp_path / "g.hdf5").W.toarray(), W, rtol=1e-13,
                               atol=1e-15)


def test_public_names() -> None:
    assert iq.load_fclib is load_fclib and iq.save_fclib is save_fclib
    assert {"load_fclib", "save_fclib"} <= set(iq.__all__)


# --- hostile files -------------------------------------------------------------------------


def _edit(path: Path, name: str, value=None) -> None:
    """Replace (or, with value None, delete) dataset ``name`` of an HDF5 file."""
    with h5py.File(path, "r+") as h:
        del h[name]
        if value is not None:
            h[name] = value


@pytest.fixture
def local_file(tmp_path: Path) -> Path:
    rng = np.random.default_rng(1)
    A = rng.standard_normal((6, 6))
    return save_fclib(FrictionContactProblem(A @ A.T, rng.standard_normal(6), 0.5),
                      tmp_path / "local.hdf5")


def test_refuses_paths(tmp_path: Path) -> None:
    with pytest.raises(ProblemFileError, match="not a regular file"):
        load_fclib(tmp_path)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(ProblemFileError, match="not a regular file"):
        load_fclib(fifo)  # refused before it is opened: no hang
    with pytest.raises(ProblemFileError, match="cannot read"):
        load_fclib(tmp_path / "absent.hdf5")
    text = tmp_path / "text.hdf5"
    text.write_text("W = [[1.0]]\n", encoding="utf-8")
    with pytest.raises(ProblemFileError, match="not an HDF5 file"):
        load_fclib(text)
    with pytest.raises(ProblemFileError, match="str or Path"):
        load_fclib(3)  # type: ignore[arg-type]
    with h5py.File(tmp_path / "other.hdf5", "w") as h:
        h["x"] = np.zeros(3)
    with pytest.raises(ProblemFileError, match="neither /fclib_local nor /fclib_global"):
        load_fclib(tmp_path / "other.hdf5")


@pytest.mark.parametrize("name, value, message", [
    ("fclib_local/vectors/q", None, "vectors/q: missing"),
    ("fclib_local/W/x", None, "W/x: missing"),
    ("fclib_local/vectors/q", np.zeros(5), "vectors/q: has 5 entries, expected 6"),
    ("fclib_local/vectors/q", np.zeros((6, 1)), "vectors/q: must be a vector"),
    ("fclib_local/vectors/q", np.array([0, 1, np.nan, 0, 0, 0.0]), "vectors/q: holds 1 non-"),
    ("fclib_local/vectors/q", np.array([b"abc"]), "vectors/q: must be a vector of numbers"),
    ("fclib_local/vectors/mu", np.array([0.5, -0.1]), "friction coefficients must be ≥ 0"),
    ("fclib_local/vectors/mu", np.array([0.5, np.inf]), "vectors/mu: holds 1 non-finite"),
    ("fclib_local/vectors/mu", np.array([0.5, 0.5, 0.5]), "vectors/mu: has 3 entries"),
    ("fclib_local/spacedim", np.array([4], dtype=np.int32), "spacedim: must be 2 or 3"),
    ("fclib_local/spacedim", np.array([3.0]), "spacedim: must hold one integer"),
    ("fclib_local/W/nz", np.array([-3], dtype=np.int32), "W/nz: -3 is not a storage"),
    ("fclib_local/W/m", np.array([2_000_000_000], dtype=np.int32), "W/m: 2000000000 is out"),
    ("fclib_local/W/n", np.array([7], dtype=np.int32), "W/p: has 7 entries, needs at least 8"),
    ("fclib_local/W/i", np.full(36, 6, dtype=np.int32), r"W/i: indices must lie in \[0, 6\)"),
    ("fclib_local/W/p", np.arange(7, dtype=np.int32)[::-1], "never decrease"),
    ("fclib_local/W/p", np.array([0, 6, 12, 18, 24, 30, 40], dtype=np.int32),
     "W/i: has 36 entries, needs at least 40"),
    ("fclib_local/W/x", np.full(36, np.nan), "W/x: holds 36 non-finite"),
    ("fclib_local/W", None, "W/m: missing"),
])
def test_refuses_bad_datasets(local_file: Path, name: str, value, message: str) -> None:
    _edit(local_file, name, value)
    with pytest.raises(ProblemFileError, match=message) as info:
        load_fclib(local_file)
    assert str(local_file) in str(info.value)


def test_refuses_group_for_dataset(local_file: Path) -> None:
    with h5py.File(local_file, "r+") as h:
        del h["fclib_local/vectors/q"]
        h.create_group("fclib_local/vectors/q")
    with pytest.raises(ProblemFileError, match="vectors/q: is a group"):
        load_fclib(local_file)


def test_refuses_non_square_and_uneven_local(tmp_path: Path) -> None:
    path = tmp_path / "w.hdf5"
    with h5py.File(path, "w") as h:
        root = h.create_group("fclib_local")
        root["spacedim"] = np.array([3], dtype=np.int32)
        _write_matrix(root.create_group("W"), np.eye(6)[:5], "csc")
        root["vectors/q"], root["vectors/mu"] = np.zeros(5), np.zeros(2)
    with pytest.raises(ProblemFileError, match="W: must be square"):
        load_fclib(path)
    with h5py.File(path, "r+") as h:
        del h["fclib_local/W"]
        _write_matrix(h.create_group("fclib_local/W"), np.eye(5), "csc")
    with pytest.raises(ProblemFileError, match="do not split into contacts of dimension 3"):
        load_fclib(path)


def test_refuses_bad_global(tmp_path: Path) -> None:
    path = tmp_path / "g.hdf5"
    _write_global(path, G=np.zeros(1))
    with pytest.raises(ProblemFileError, match="fclib_global/G: mixed problems"):
        load_fclib(path)
    _write_global(path)
    _edit(path, "fclib_global/vectors/f", np.zeros(3))
    with pytest.raises(ProblemFileError, match="vectors/f: has 3 entries, expected 4"):
        load_fclib(path)
    M = _tiny_global()[0]
    singular = M.copy()
    singular[3] = singular[2] = M[2]
    for storage in ("triplet", "csc"):
        _write_global(path, storage)
        with h5py.File(path, "r+") as h:
            del h["fclib_global/M"]
            _write_matrix(h.create_group("fclib_global/M"), singular, storage)
        with pytest.raises(ProblemFileError, match="fclib_global/M: is singular"):
            load_fclib(path)
    _write_global(path)
    with h5py.File(path, "r+") as h:
        del h["fclib_global/H"]
        _write_matrix(h.create_group("fclib_global/H"), np.ones((3, 6)), "csc")
    with pytest.raises(ProblemFileError, match="H: must have 4 rows"):
        load_fclib(path)


def test_refuses_mixed_local(local_file: Path) -> None:
    with h5py.File(local_file, "r+") as h:
        h["fclib_local/vectors/s"] = np.zeros(1)
    with pytest.raises(ProblemFileError, match="vectors/s: mixed problems"):
        load_fclib(local_file)


def test_save_refuses(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="must be a FrictionContactProblem"):
        save_fclib(np.eye(3), tmp_path / "x.hdf5")  # type: ignore[arg-type]
    problem = FrictionContactProblem(np.eye(3), np.zeros(3), 0.5)
    with pytest.raises(InputError, match="not a regular file"):
        save_fclib(problem, tmp_path)
    problem.q = np.array([0.0, np.nan, 0.0])
    with pytest.raises(InputError, match="problem.q holds non-finite"):
        save_fclib(problem, tmp_path / "nan.hdf5")
    assert not (tmp_path / "nan.hdf5").exists()


def test_damaged_files_are_refused_by_name(tmp_path: Path) -> None:
    """Truncated and byte-flipped copies of a shipped file: each either loads (the bytes hit
    unused space or a value that stays valid) or is a ProblemFileError, never h5py's own
    exception; at least the truncated ones are refused."""
    source = (DATA / "LMGC_GlobalFrictionContactProblem00046.hdf5").read_bytes()
    rng = np.random.default_rng(3)
    path = tmp_path / "damaged.hdf5"
    refused = 0
    for k in range(80):
        data = bytearray(source[:int(rng.integers(0, len(source) // 2))] if k < 20 else source)
        for _ in range(0 if k < 20 else int(rng.integers(1, 10))):
            data[int(rng.integers(0, len(data)))] = int(rng.integers(0, 256))
        path.write_bytes(bytes(data))
        try:
            problem = load_fclib(path)
        except ProblemFileError:
            refused += 1
            continue
        assert np.all(np.isfinite(problem.W.data)) and np.all(np.isfinite(problem.q))
        assert np.all(problem.mu >= 0)
    assert refused >= 20


@pytest.mark.parametrize("name", ["Box_Stacks-i0122-82-5.hdf5",
                                  "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5",
                                  "LMGC_GlobalFrictionContactProblem00046.hdf5"])
def test_shipped_problems_are_solved_and_certified(name):
    """The small FCLib problems of Siconos' test data (global ones reduced) are solved by
    the default route to ABH ≤ 1e-8, the certificate recomputed from (W, q, μ, r) alone."""
    problem = iq.load_fclib(DATA / name)
    result = iq.solve_friction(problem, tol=1e-8)
    assert result.certificate.ok and result.error <= 1e-8
    u = problem.W @ result.r + problem.q
    np.testing.assert_allclose(result.u, u, atol=1e-8 * np.linalg.norm(problem.q))
