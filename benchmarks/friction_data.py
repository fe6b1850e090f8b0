"""The friction suite's problems: FCLib HDF5 files and Siconos' text files of local problems.

HDF5 files are read by :func:`impactqp.load_fclib` (global ones reduced to local ones by
W = Hᵀ M⁻¹ H, q = Hᵀ M⁻¹ f + w). Siconos' text files (``*.dat``, kept gzip-compressed,
byte-identical once decompressed; see benchmarks/data/fclib/README.md) hold the local
problem as Siconos writes it (``frictionContact_printInFile``): the dimension d, the number
of contacts, the matrix W (storage 0 dense, or 1 sparse-block, both column-major), then q
and μ. :func:`read_siconos_text` parses that layout into a
:class:`~impactqp.FrictionContactProblem`.
"""

from __future__ import annotations

import gzip
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

import impactqp as iq

ROOT = Path(__file__).resolve().parents[1]
TESTS_FCLIB = ROOT / "tests" / "data" / "fclib"
BENCH_FCLIB = Path(__file__).resolve().parent / "data" / "fclib"

#: short name → file (tests/data/fclib or benchmarks/data/fclib)
FILES: dict[str, Path] = {
    "LMGC-00046": TESTS_FCLIB / "LMGC_GlobalFrictionContactProblem00046.hdf5",
    "NESpheres-10": BENCH_FCLIB / "NESpheres_10_1.dat.gz",
    "BoxesStack1": BENCH_FCLIB / "BoxesStack1-i100000-32.hdf5.dat.gz",
    "PerioBox": TESTS_FCLIB / "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5",
    "Box_Stacks": TESTS_FCLIB / "Box_Stacks-i0122-82-5.hdf5",
    "spheres-in-a-box": TESTS_FCLIB / "spheres-in-a-box-98-i10000-256-10.hdf5",
    "Capsules": TESTS_FCLIB / "Capsules-i125-1213.hdf5",
    "Spheres": BENCH_FCLIB / "Spheres-i099-356-679.hdf5",
    "KaplasTower": BENCH_FCLIB / "KaplasTower-i1061-4.hdf5.dat.gz",
}


@dataclass
class FrictionCase:
    """One problem of the friction suite, loaded before any timer starts.

    Attributes
    ----------
    name : str
        Short name (a key of :data:`FILES`).
    path : Path
        Where it was read from.
    problem : FrictionContactProblem
        W, q, μ as impactqp reads them (the same arrays go to Siconos).
    """

    name: str
    path: Path
    problem: iq.FrictionContactProblem

    @property
    def n_contacts(self) -> int:
        return self.problem.n_contacts

    @property
    def family(self) -> str:
        """The family of its rows in results.csv (one per problem)."""
        return f"friction:{self.name}"


def load(name: str) -> FrictionCase:
    """Read the suite's problem ``name`` (a key of :data:`FILES`)."""
    path = FILES[name]
    if path.suffix == ".hdf5":
        problem = iq.load_fclib(path)
    else:
        problem = read_siconos_text(path)
    return FrictionCase(name, path, problem)


def _numbers(path: Path) -> list[str]:
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rt") as fh:
        return fh.read().split()


def read_siconos_text(path: Path | str) -> iq.FrictionContactProblem:
    """The local problem of a Siconos text file (``frictionContact_printInFile``'s layout).

    Parameters
    ----------
    path : path
        ``.dat`` or gzip-compressed ``.dat.gz``.

    Returns
    -------
    FrictionContactProblem
        W sparse (CSR) when stored sparse-block, dense otherwise.

    Raises
    ------
    ValueError
        A storage other than dense or sparse-block, or a file shorter than its header says.
    """
    path = Path(path)
    tok = _numbers(path)
    pos = 0

    def take(k: int) -> list[str]:
        nonlocal pos
        if pos + k > len(tok):
            raise ValueError(f"{path}: ends after {len(tok)} numbers, expected more")
        out = tok[pos:pos + k]
        pos += k
        return out

    d, nc, storage, n0, n1 = (int(t) for t in take(5))
    if storage == 0:
        r, c = (int(t) for t in take(2))
        W = np.array(take(r * c), dtype=float).reshape(c, r).T  # column-major
    elif storage == 1:
        W = _sparse_block(take, n0, n1)
    else:
        raise ValueError(f"{path}: matrix storage {storage} is neither dense (0) nor "
                         "sparse-block (1)")
    q = np.array(take(n0), dtype=float)
    mu = np.array(take(nc), dtype=float)
    return iq.FrictionContactProblem(W, q, mu, contact_dim=d)


def _sparse_block(take, n0: int, n1: int) -> sp.csr_matrix:
    """Siconos' sparse-block matrix: block row/column ends, CSR of the blocks, then each
    block's number and its entries column by column."""
    nblocks, rows_b, cols_b = (int(t) for t in take(3))
    row_end = [int(t) for t in take(rows_b)]
    col_end = [int(t) for t in take(cols_b)]
    filled1, filled2 = (int(t) for t in take(2))
    rowptr = [int(t) for t in take(filled1)]
    colidx = [int(t) for t in take(filled2)]
    if filled2 != nblocks:
        raise ValueError(f"{filled2} block indices for {nblocks} blocks")
    row_start, col_start = [0, *row_end[:-1]], [0, *col_end[:-1]]
    rows, cols, vals = [], [], []
    for bi in range(filled1 - 1):
        for k in range(rowptr[bi], rowptr[bi + 1]):
            bj = colidx[k]
            take(1)  # the block's own number
            h, w = row_end[bi] - row_start[bi], col_end[bj] - col_start[bj]
            block = np.array(take(h * w), dtype=float).reshape(w, h).T
            i, j = np.nonzero(block)
            rows.append(i + row_start[bi])
            cols.append(j + col_start[bj])
            vals.append(block[i, j])
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(n0, n1))


def write_siconos_text(problem: iq.FrictionContactProblem, path: Path | str, *,
                       storage: int = 1) -> None:
    """Write ``problem`` in the layout :func:`read_siconos_text` reads (and Siconos'
    ``frictionContact_new_from_filename``): storage 1 sparse-block with one d × d block per
    pair of contacts that couple (Siconos' own storage of a Delassus operator), 0 dense.

    Numbers are written with 17 significant digits, so they read back bit for bit.
    """
    d, m = problem.contact_dim, problem.n_contacts
    n = d * m
    W = problem.dense_W()
    out = [str(d), str(m), str(storage), str(n), str(n)]
    if storage == 0:
        out.append(f"{n}\t{n}")
        out.append(" ".join(f"{x:.17e}" for x in W.T.ravel()))
    elif storage == 1:
        blocks = W.reshape(m, d, m, d).transpose(0, 2, 1, 3)  # [row contact, column contact]
        filled = np.abs(blocks).sum(axis=(2, 3)) > 0
        rowptr = np.concatenate([[0], np.cumsum(filled.sum(axis=1))])
        bi, bj = np.nonzero(filled)
        ends = "\t".join(str(d * (c + 1)) for c in range(m))
        out += [str(bi.size), str(m), str(m), ends, ends, str(m + 1), str(bi.size),
                "\t".join(map(str, rowptr)), "\t".join(map(str, bj))]
        for k, (i, j) in enumerate(zip(bi, bj)):
            out.append(str(k))
            out.append(" ".join(f"{x:.17e}" for x in blocks[i, j].T.ravel()))
    else:
        raise ValueError(f"storage must be 0 (dense) or 1 (sparse-block), got {storage}")
    out.append(" ".join(f"{x:.17e}" for x in problem.q))
    out.append(" ".join(f"{x:.17e}" for x in problem.mu))
    Path(path).write_text("\n".join(out) + "\n")
