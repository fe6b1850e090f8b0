"""FCLib files: frictional contact problems in HDF5, read and written with h5py (and, through
the same :func:`load_fclib`, Siconos' text files of them: :mod:`.siconos_text`).

FCLib (Acary, Brémond, Huber et al.) stores one problem per file, in one of two forms:

- ``/fclib_local``: the local problem u = W r + q (``W``, ``vectors/q``, ``vectors/mu``,
  ``spacedim``), read as it is;
- ``/fclib_global``: M v = H r + f, u = Hᵀ v + w (``M``, ``H``, ``vectors/f``, ``vectors/w``,
  ``vectors/mu``, ``spacedim``), reduced to the local problem by eliminating v:
  W = Hᵀ M⁻¹ H, q = Hᵀ M⁻¹ f + w. This is the Delassus matrix and free contact velocity of
  docs/theory.md §1 with H in the role of the force directions and M⁻¹f in that of u⁻
  (:mod:`.fclib_reduce`: sparse for a block-diagonal M, by dense blocks under a work limit
  otherwise).

Per contact the d = ``spacedim`` (2 or 3) entries are the normal first, then the tangents;
μ has one entry per contact. A matrix is a group ``nzmax, m, n, nz, p, i, x`` in the
CSparse layout: ``nz = -1`` compressed columns (``p`` the n + 1 column pointers, ``i`` the
row indices), ``nz = -2`` compressed rows (``p`` the m + 1 row pointers, ``i`` the column
indices), ``nz ≥ 0`` a triplet of ``nz`` entries (``i`` the row, ``p`` the column of each;
duplicates add up, as in CSparse). Mixed problems (``V``, ``R``, ``s`` or ``G``, ``b``: extra
equality multipliers) are refused, as are rolling-friction files.

Reading is strict: a path that is not a regular file, a file that is not HDF5, missing or
mis-typed datasets, sizes that do not fit together, indices out of range, non-finite
numbers, negative μ, a W with a negative diagonal entry (no Delassus matrix has one) and an
M that is singular or not positive definite (no mass matrix is) are refused with a
:class:`~impactqp.errors.ProblemFileError` that names the file and the dataset. A file is
read alone: external links (which open other files, a FIFO among them, where reading would
wait forever), soft links, external raw storage (a dataset whose bytes live in another file,
/dev/zero reads as zeros) and virtual datasets are refused by name, before anything they
point at is opened (:mod:`.hdf5_reader`). Dimensions above :data:`MAX_FCLIB_DIM` and
datasets declaring more than :data:`~impactqp.io.hdf5_reader.MAX_DATASET_BYTES` are refused
before anything is allocated or decompressed, and only the entries the problem needs are
read.
"""

from __future__ import annotations

import stat
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..base.outputs import atomic_output
from ..errors import InputError, ProblemFileError
from ..model.friction import FrictionContactProblem
from .delassus import negative_diagonal
from .fclib_reduce import reduce_global
from .hdf5_reader import CheckedReader, h5py_module
from .siconos_text import looks_like_siconos_text, read_siconos_text

MAX_FCLIB_DIM = 1_000_000
"""Largest row or column count of a matrix in an FCLib file (degrees of freedom, d·contacts)."""

MIXED_PARTS = {"fclib_local": ("V", "R", "vectors/s"), "fclib_global": ("G", "vectors/b")}


class _Reader(CheckedReader):
    """The CSparse matrices, ``spacedim`` and μ of an FCLib file, each checked."""

    def matrix(self, name: str) -> sp.csc_matrix:
        """The sparse matrix stored in group ``name`` (CSparse layout, see the module doc)."""
        m, n, nz = (self.integer(f"{name}/{key}") for key in ("m", "n", "nz"))
        for key, value in (("m", m), ("n", n)):
            if not 0 <= value <= MAX_FCLIB_DIM:
                raise self.error(f"{name}/{key}", f"{value} is outside [0, {MAX_FCLIB_DIM}]")
        if nz >= 0:
            rows = self.indices(f"{name}/i", nz, m)
            cols = self.indices(f"{name}/p", nz, n)
            values = self.floats(f"{name}/x", nz, exact=False)
            return sp.csc_matrix((values, (rows, cols)), shape=(m, n))
        if nz not in (-1, -2):
            raise self.error(f"{name}/nz", f"{nz} is not a storage FCLib knows (-1 compressed "
                                           "columns, -2 compressed rows, ≥ 0 triplet)")
        outer, inner = (n, m) if nz == -1 else (m, n)
        pointers = self.indices(f"{name}/p", outer + 1, np.iinfo(np.int64).max)
        if pointers[0] != 0 or np.any(np.diff(pointers) < 0):
            raise self.error(f"{name}/p", "pointers must start at 0 and never decrease")
        count = int(pointers[-1])
        index = self.indices(f"{name}/i", count, inner)
        values = self.floats(f"{name}/x", count, exact=False)
        kind = sp.csc_matrix if nz == -1 else sp.csr_matrix
        return sp.csc_matrix(kind((values, index, pointers), shape=(m, n)))

    def spacedim(self, root: str) -> int:
        d = self.integer(f"{root}/spacedim")
        if d not in (2, 3):
            raise self.error(f"{root}/spacedim", f"must be 2 or 3, got {d}")
        return d

    def mu(self, root: str, contacts: int) -> np.ndarray:
        mu = self.floats(f"{root}/vectors/mu", contacts)
        if np.any(mu < 0):
            raise self.error(f"{root}/vectors/mu", "friction coefficients must be ≥ 0, found "
                                                   f"{mu.min()}")
        return mu


def _contacts(reader: _Reader, name: str, size: int, d: int) -> int:
    if size % d:
        raise reader.error(name, f"{size} rows or columns do not split into contacts of "
                                 f"dimension {d}")
    return size // d


def _local(reader: _Reader) -> tuple[sp.csc_matrix, np.ndarray, np.ndarray, int]:
    root = "fclib_local"
    d = reader.spacedim(root)
    W = reader.matrix(f"{root}/W")
    if W.shape[0] != W.shape[1]:
        raise reader.error(f"{root}/W", f"must be square, got {W.shape}")
    contacts = _contacts(reader, f"{root}/W", W.shape[0], d)
    negative = negative_diagonal(W, d)
    if negative is not None:
        raise reader.error(f"{root}/W", negative)
    q = reader.floats(f"{root}/vectors/q", W.shape[0])
    return W, q, reader.mu(root, contacts), d


def _global(reader: _Reader) -> tuple[sp.csc_matrix, np.ndarray, np.ndarray, int]:
    root = "fclib_global"
    d = reader.spacedim(root)
    M = reader.matrix(f"{root}/M")
    if M.shape[0] != M.shape[1]:
        raise reader.error(f"{root}/M", f"must be square, got {M.shape}")
    H = reader.matrix(f"{root}/H")
    if H.shape[0] != M.shape[0]:
        raise reader.error(f"{root}/H", f"must have {M.shape[0]} rows (those of M), got "
                                        f"{H.shape[0]}")
    contacts = _contacts(reader, f"{root}/H", H.shape[1], d)
    f = reader.floats(f"{root}/vectors/f", M.shape[0])
    w = reader.floats(f"{root}/vectors/w", H.shape[1])
    mu = reader.mu(root, contacts)
    W, Hf = reduce_global(M, H, f, lambda what: reader.error(f"{root}/M", what))
    return W, Hf + w, mu, d


def _read(reader: _Reader) -> tuple[sp.csc_matrix, np.ndarray, np.ndarray, int]:
    root = next((r for r in ("fclib_local", "fclib_global") if reader.contains(r)), None)
    if root is None:
        raise ProblemFileError(f"{reader.path}: neither /fclib_local nor /fclib_global; not an "
                               "FCLib problem file")
    mixed = [part for part in MIXED_PARTS[root] if reader.contains(f"{root}/{part}")]
    if mixed:
        raise reader.error(f"{root}/{mixed[0]}", "mixed problems (extra equality multipliers) "
                                                 "are not supported")
    return _local(reader) if root == "fclib_local" else _global(reader)


def load_fclib(path: str | Path) -> FrictionContactProblem:
    """Read a frictional contact problem from an FCLib HDF5 file or a Siconos text file.

    The content decides, not the name: a file that is gzip-compressed or starts with a
    number is read as Siconos' text layout (``.dat``, ``.dat.gz``;
    :func:`~impactqp.io.siconos_text.read_siconos_text`, as strictly as HDF5), any other as
    FCLib HDF5. A local problem (``/fclib_local``) is returned as stored; a global one
    (``/fclib_global``: M v = H r + f, u = Hᵀ v + w) is reduced to the local form
    u = W r + q with W = Hᵀ M⁻¹ H and q = Hᵀ M⁻¹ f + w (docs/theory.md §1). A file holding
    both is read as local.

    Parameters
    ----------
    path : str or Path
        An FCLib file (``.hdf5``) or a Siconos text file (``.dat``, ``.dat.gz``).

    Returns
    -------
    FrictionContactProblem
        W as a scipy.sparse CSC matrix (from HDF5; a Siconos text file gives W as stored:
        dense, or CSR from sparse blocks), q, μ (one per contact) and ``contact_dim``
        (FCLib's ``spacedim``, Siconos' d).

    Raises
    ------
    ProblemFileError
        Not a regular file, not HDF5, neither problem group, a mixed problem (``V``/``R`` or
        ``G``/``b``), a missing or malformed dataset, non-finite numbers, negative μ, a negative
        diagonal entry of W, or an M that is singular or not positive definite; a link that is not
        a hard one (an external link reaches into another file), a dataset stored outside the file
        (external raw storage, a virtual dataset), one declaring more than
        :data:`~impactqp.io.hdf5_reader.MAX_DATASET_BYTES`, or a problem that does not fit in
        memory. The message names the file and the dataset.
        For a Siconos text file: the errors of
        :func:`~impactqp.io.siconos_text.read_siconos_text` (truncated, non-numeric or
        non-finite numbers, counts that do not fit, negative μ, a damaged gzip stream), each
        naming the file, the field and the position of the number.
    """
    if not isinstance(path, (str, Path)):
        raise ProblemFileError(f"path must be a str or Path, got {type(path).__name__}")
    path = Path(path)
    try:
        if not stat.S_ISREG(path.stat().st_mode):
            raise ProblemFileError(f"{path}: not a regular file")
        with path.open("rb") as raw:
            head = raw.read(64)
    except OSError as exc:
        raise ProblemFileError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if not head:
        raise ProblemFileError(f"{path}: empty; neither an FCLib (HDF5) nor a Siconos text "
                               "problem file")
    if looks_like_siconos_text(head):
        try:
            return read_siconos_text(path)
        except MemoryError:
            raise ProblemFileError(f"{path}: the problem does not fit in this machine's "
                                   "memory") from None
    h5py = h5py_module()
    try:
        if not h5py.is_hdf5(path):
            raise ProblemFileError(f"{path}: not an HDF5 file (FCLib) nor a Siconos text "
                                   "problem file (.dat, .dat.gz: it starts with a number)")
        handle = h5py.File(path, "r")
    except OSError as exc:
        raise ProblemFileError(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        with handle:
            try:
                W, q, mu, d = _read(_Reader(path, handle))
            except ProblemFileError:
                raise
            except (OSError, RuntimeError, KeyError, ValueError) as exc:  # h5py, damaged file
                raise ProblemFileError(f"{path}: damaged HDF5 file ({exc})") from None
        return FrictionContactProblem(W, q, mu, contact_dim=d)
    except MemoryError:
        raise ProblemFileError(f"{path}: the problem does not fit in this machine's memory")\
            from None
    except ProblemFileError:
        raise
    except InputError as exc:
        raise ProblemFileError(f"{path}: {exc}") from exc


def _write_int(group: Any, name: str, value: int) -> None:
    group.create_dataset(name, data=np.array([value], dtype=np.int32))


def save_fclib(problem: FrictionContactProblem, path: str | Path) -> Path:
    """Write a local frictional contact problem as an FCLib HDF5 file (``/fclib_local``).

    W is stored in compressed columns (``nz = -1``), as FCLib and Siconos read it. The file
    is written beside ``path`` and renamed onto it when complete, so an existing file is
    replaced whole or, when writing fails, left as it was. :func:`load_fclib` reads back W,
    q and μ bit for bit.

    Parameters
    ----------
    problem : FrictionContactProblem
        The problem u = W r + q; W dense or scipy.sparse.
    path : str or Path
        Where to write (``.hdf5``).

    Returns
    -------
    Path
        The path written.

    Raises
    ------
    InputError
        ``problem`` is not a FrictionContactProblem, holds non-finite numbers, or ``path``
        exists and is not a regular file.
    """
    if not isinstance(problem, FrictionContactProblem):
        raise InputError(f"problem must be a FrictionContactProblem, got "
                         f"{type(problem).__name__}")
    W = sp.csc_matrix(problem.W, dtype=float)
    W.sort_indices()
    q = np.asarray(problem.q, dtype=float)
    mu = np.asarray(problem.mu, dtype=float)
    for name, values in (("W", W.data), ("q", q), ("mu", mu)):
        if not np.all(np.isfinite(values)):
            raise InputError(f"problem.{name} holds non-finite numbers; FCLib files hold "
                             "finite ones")
    path = Path(path)
    h5py = h5py_module()
    try:
        with atomic_output(path) as temp, h5py.File(temp, "w") as handle:
            root = handle.create_group("fclib_local")
            _write_int(root, "spacedim", problem.contact_dim)
            group = root.create_group("W")
            for key, value in (("nzmax", W.nnz), ("m", W.shape[0]), ("n", W.shape[1]),
                               ("nz", -1)):
                _write_int(group, key, value)
            group.create_dataset("p", data=W.indptr.astype(np.int32))
            group.create_dataset("i", data=W.indices.astype(np.int32))
            group.create_dataset("x", data=W.data)
            vectors = root.create_group("vectors")
            vectors.create_dataset("q", data=q)
            vectors.create_dataset("mu", data=mu)
            info = root.create_group("info")
            info.create_dataset("title", data=np.bytes_("impactqp"))
            info.create_dataset("description", data=np.bytes_("written by impactqp.save_fclib"))
            info.create_dataset("math_info", data=np.bytes_(""))
    except OSError as exc:
        raise InputError(f"cannot write {path}: {exc.strerror or exc}") from None
    return path
