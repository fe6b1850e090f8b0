"""Siconos' text files of frictional contact problems (``.dat``, gzip-compressed ``.dat.gz``),
read strictly and written in the same layout.

The layout is that of Siconos' ``frictionContact_printInFile`` and
``frictionContact_newFromFile``: numbers separated by white space (spaces, tabs, new lines),

1. d (2 or 3) and the number of contacts m;
2. the matrix W as ``NM_write_in_file`` writes it: its storage (0 dense, 1 sparse-block), the
   sizes n₀ and n₁, then

   - dense: n₀ and n₁ again and the n₀·n₁ entries column by column;
   - sparse-block: the number of blocks, the numbers of block rows and block columns, the
     cumulated sizes of the block rows and of the block columns, the lengths of the two index
     arrays (block rows + 1, blocks), the block-row pointers, the block-column index of each
     block, then each block as its own number followed by its entries column by column;
   - compressed sparse (``NM_SPARSE``, read by :mod:`.csparse_text`): the origin of the
     matrix (1 triplet, 2 compressed columns, 3 compressed rows), then CSparse's own print
     of it: a banner line (``CSparse Version …``), a header
     (``[triplet:|csr:] n₀-by-n₁, nzmax: … nnz: …``), then each entry as ``i j : x``
     (triplet) or, per column (row), ``col j : locations a to b`` followed by its b − a + 1
     entries ``i : x``. CSparse prints the entries with six significant digits (``%g``):
     the problem is the one of the rounded numbers, as Siconos itself reads it back;

3. q (n₁ numbers) and μ (m numbers), then, in files Siconos wrote before 2010, one flag
   (0 or 1, the problem's former ``isComplete`` field, which Siconos' reader skips).

Reading is as strict as that of FCLib's HDF5 files (:mod:`.fclib`): every count is checked
against the others (n₀ = n₁ = d·m, pointers from 0 that never decrease, block indices in
range, blocks numbered in order, the compressed-sparse header's sizes, pointers and indices),
every number must be finite, μ ≥ 0, and nothing but the old 0/1 flag may follow μ (numbers
left over mean that a count is wrong). Errors are
:class:`~impactqp.errors.ProblemFileError` naming the file, the field and the position of the
offending number. Files are read whole into memory, and refused above
:data:`MAX_TEXT_BYTES` (once decompressed) before any number is parsed. Siconos' half-triplet
origin (the lower half of a symmetric matrix) is refused by name.
"""

from __future__ import annotations

import gzip
import zlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..base.outputs import atomic_output
from ..errors import InputError, ProblemFileError
from ..model.friction import FrictionContactProblem
from .csparse_text import read_compressed_sparse
from .delassus import negative_diagonal
from .text_numbers import TextNumbers, is_float

MAX_TEXT_BYTES = 2**27
"""Largest Siconos text file read, in bytes once decompressed (128 MiB, some five million
numbers; the largest problems of Siconos' test data are a few MB)."""

MAX_SIZE = 1_000_000
"""Largest row or column count of W (degrees of freedom, d·contacts), as for FCLib files."""

GZIP_MAGIC = b"\x1f\x8b"
"""The first two bytes of a gzip stream."""

STORAGES = {0: "dense", 1: "sparse-block", 2: "compressed sparse"}
"""W's storages read; the first two are written."""
WRITTEN = (0, 1)
"""W's storages :func:`write_siconos_text` writes."""

def looks_like_siconos_text(head: bytes) -> bool:
    """True when a file starting with ``head`` is gzip-compressed or starts (after white space)
    with a digit or a sign: the first number of a Siconos text file. HDF5 files start with
    their signature (or a user block), never with a number."""
    if head.startswith(GZIP_MAGIC):
        return True
    first = head.lstrip()[:1]
    return first != b"" and first in b"0123456789+-"


def _text(path: Path) -> str:
    """The file's text, decompressed when it is gzip, at most :data:`MAX_TEXT_BYTES`."""
    compressed = False
    try:
        with path.open("rb") as raw:
            compressed = raw.read(2) == GZIP_MAGIC
            raw.seek(0)
            stream = gzip.GzipFile(fileobj=raw) if compressed else raw
            data = stream.read(MAX_TEXT_BYTES + 1)
    except (OSError, EOFError, zlib.error) as exc:  # BadGzipFile is an OSError
        what = "damaged gzip stream" if compressed else "cannot read"
        raise ProblemFileError(f"{path}: {what} ({exc})") from None
    if len(data) > MAX_TEXT_BYTES:
        raise ProblemFileError(f"{path}: more than {MAX_TEXT_BYTES} bytes of text"
                               f"{' once decompressed' if compressed else ''}; Siconos text "
                               "files above that are refused before parsing")
    try:
        return data.decode("ascii")
    except UnicodeDecodeError as exc:
        raise ProblemFileError(f"{path}: not a Siconos text problem file: byte {exc.start} "
                               "is not ASCII text") from None


def _dense(numbers: TextNumbers, n0: int, n1: int) -> np.ndarray:
    numbers.integer("W's rows (dense)", n0, n0)
    numbers.integer("W's columns (dense)", n1, n1)
    return numbers.floats("W (dense, column by column)", n0 * n1).reshape(n1, n0).T


def _ends(numbers: TextNumbers, field: str, count: int, size: int) -> np.ndarray:
    """Cumulated block sizes: increasing, ending at ``size``."""
    ends = numbers.integers(field, count, 1, size)
    if np.any(np.diff(ends) <= 0) or ends[-1] != size:
        raise numbers.error(field, f"must increase and end at {size}, got "
                                   f"{ends[:4].tolist()}…{ends[-1]}", numbers.pos - count)
    return ends


def _blocks(numbers: TextNumbers, n0: int, n1: int) -> sp.csr_matrix:
    """A sparse-block W (see the module doc)."""
    nblocks = numbers.integer("W's number of blocks", 1, MAX_SIZE**2)
    brows = numbers.integer("W's number of block rows", 1, n0)
    bcols = numbers.integer("W's number of block columns", 1, n1)
    row_end = _ends(numbers, "W's block-row ends", brows, n0)
    col_end = _ends(numbers, "W's block-column ends", bcols, n1)
    numbers.integer("W's length of block-row pointers", brows + 1, brows + 1)
    numbers.integer("W's length of block-column indices", nblocks, nblocks)
    at = numbers.pos
    rowptr = numbers.integers("W's block-row pointers", brows + 1, 0, nblocks)
    if rowptr[0] != 0 or np.any(np.diff(rowptr) < 0) or rowptr[-1] != nblocks:
        raise numbers.error("W's block-row pointers", f"must start at 0, never decrease and "
                                                      f"end at {nblocks} blocks", at)
    colidx = numbers.integers("W's block-column indices", nblocks, 0, bcols - 1)
    row_start, col_start = np.r_[0, row_end[:-1]], np.r_[0, col_end[:-1]]
    block_row = np.repeat(np.arange(brows), np.diff(rowptr))  # of each block, in file order
    h = (row_end - row_start)[block_row]
    w = (col_end - col_start)[colidx]
    size = h * w
    first = np.r_[0, np.cumsum(size + 1)[:-1]]  # where each block's number is, from here
    at = numbers.pos
    tokens = numbers.take("W's blocks", int(first[-1] + size[-1] + 1))
    values = _block_values(numbers, tokens, first, at)
    # each entry's block, then its place in the block, column by column
    owner = np.repeat(np.arange(nblocks), size)
    local = np.arange(owner.size) - np.repeat(first - np.arange(nblocks), size)
    entries = np.delete(values, first)
    rows = row_start[block_row][owner] + local % h[owner]
    cols = col_start[colidx][owner] + local // h[owner]
    keep = entries != 0
    return sp.csr_matrix((entries[keep], (rows[keep], cols[keep])), shape=(n0, n1))


def _block_values(numbers: TextNumbers, tokens: list[str], first: np.ndarray,
                  at: int) -> np.ndarray:
    """The numbers of W's blocks (each block's own number, then its entries), all finite and
    each block numbered in order; an error names the block of the offending number."""

    def field(index: int) -> str:
        k = int(np.searchsorted(first, index, side="right")) - 1
        return f"W's block {k} number" if first[k] == index else \
            f"W's block {k} (column by column)"

    for k, index in enumerate(first.tolist()):
        token = tokens[index]
        if token != str(k) and not (token.lstrip("+").isdigit() and int(token) == k):
            what = f"{token} is outside [{k}, {k}]" if token.lstrip("+-").isdigit() else \
                f"{token!r} is not an integer"
            raise numbers.error(field(index), what, at + index)
    try:
        values = np.array(tokens, dtype=float)
    except ValueError:
        bad = next(k for k, t in enumerate(tokens) if not is_float(t))
        raise numbers.error(field(bad), f"{tokens[bad]!r} is not a number", at + bad) from None
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise numbers.error(field(int(bad[0])), f"holds {bad.size} non-finite number(s) (NaN "
                                                "or infinity), the first here", at + int(bad[0]))
    return values


def read_siconos_text(path: str | Path) -> FrictionContactProblem:
    """Read the local frictional contact problem of a Siconos text file.

    Parameters
    ----------
    path : str or Path
        ``.dat``, or ``.dat.gz`` (any gzip-compressed file is decompressed).

    Returns
    -------
    FrictionContactProblem
        W sparse (CSR) when stored sparse-block or compressed sparse, dense otherwise; q, μ
        and ``contact_dim`` d.

    Raises
    ------
    ProblemFileError
        An unreadable file or damaged gzip stream, text that is not ASCII, a missing or
        non-numeric number, a count that does not fit the others (n₀ ≠ d·m, block pointers,
        indices, block numbers, a compressed-sparse header, location or index out of place,
        numbers left over after μ beyond Siconos' old 0/1 flag), a storage other than dense,
        sparse-block or compressed sparse, a half-triplet W, non-finite numbers, negative μ,
        a negative diagonal entry of W (no Delassus matrix has one), or more than
        :data:`MAX_TEXT_BYTES` of text. The message names the file, the field and the
        position of the number.
    """
    path = Path(path)
    numbers = TextNumbers(path, _text(path))
    if not numbers.tokens:
        raise ProblemFileError(f"{path}: empty; not a Siconos text problem file")
    d = numbers.integer("d, the dimension of a contact", 2, 3)
    m = numbers.integer("the number of contacts", 1, MAX_SIZE // d)
    storage = numbers.integer("W's storage", 0, 2)
    n0 = numbers.integer("W's rows", d * m, d * m)
    n1 = numbers.integer("W's columns", d * m, d * m)
    W = (_dense, _blocks, read_compressed_sparse)[storage](numbers, n0, n1)
    q = numbers.floats("q", n1)
    at = numbers.pos
    mu = numbers.floats("μ", m)
    if np.any(mu < 0):
        raise numbers.error("μ", f"friction coefficients must be ≥ 0, found {mu.min()}",
                            at + int(np.argmin(mu)))
    numbers.finish()
    negative = negative_diagonal(W, d)
    if negative is not None:
        raise ProblemFileError(f"{path}: W: {negative}")
    try:
        return FrictionContactProblem(W, q, mu, contact_dim=d)
    except InputError as exc:
        raise ProblemFileError(f"{path}: {exc}") from exc


def _lines(problem: FrictionContactProblem, storage: int) -> Iterator[str]:
    d, m = problem.contact_dim, problem.n_contacts
    n = d * m
    W = problem.dense_W()
    yield from (str(d), str(m), str(storage), str(n), str(n))
    if storage == 0:
        yield f"{n}\t{n}"
        yield " ".join(f"{x:.17e}" for x in W.T.ravel())
        return
    blocks = W.reshape(m, d, m, d).transpose(0, 2, 1, 3)  # [row contact, column contact]
    filled = np.abs(blocks).sum(axis=(2, 3)) > 0
    filled[np.arange(m), np.arange(m)] = True  # at least one block per block row
    rowptr = np.concatenate([[0], np.cumsum(filled.sum(axis=1))])
    bi, bj = np.nonzero(filled)
    ends = "\t".join(str(d * (c + 1)) for c in range(m))
    yield from (str(bi.size), str(m), str(m), ends, ends, str(m + 1), str(bi.size),
                "\t".join(map(str, rowptr)), "\t".join(map(str, bj)))
    for k, (i, j) in enumerate(zip(bi, bj, strict=True)):
        yield str(k)
        yield " ".join(f"{x:.17e}" for x in blocks[i, j].T.ravel())


def write_siconos_text(problem: FrictionContactProblem, path: str | Path, *,
                       storage: int = 1) -> Path:
    """Write ``problem`` in Siconos' text layout (read by :func:`read_siconos_text` and by
    Siconos' ``frictionContact_new_from_filename``).

    Parameters
    ----------
    problem : FrictionContactProblem
        The local problem u = W r + q.
    path : str or Path
        Where to write (``.dat``); written beside it and renamed onto it when complete.
    storage : int
        1 sparse-block (one d × d block per pair of contacts that couple, Siconos' own
        storage of a Delassus operator) or 0 dense.

    Returns
    -------
    Path
        The path written. Numbers have 17 significant digits: they read back bit for bit.

    Raises
    ------
    InputError
        Another storage, or ``problem`` is not a FrictionContactProblem.
    """
    if storage not in WRITTEN:
        raise InputError(f"storage must be 0 (dense) or 1 (sparse-block), got {storage!r}")
    if not isinstance(problem, FrictionContactProblem):
        raise InputError(f"problem must be a FrictionContactProblem, got "
                         f"{type(problem).__name__}")
    lines = [*_lines(problem, storage),
             " ".join(f"{x:.17e}" for x in np.asarray(problem.q, dtype=float)),
             " ".join(f"{x:.17e}" for x in np.asarray(problem.mu, dtype=float))]
    path = Path(path)
    with atomic_output(path) as temp:
        Path(temp).write_text("\n".join(lines) + "\n", encoding="ascii")
    return path
