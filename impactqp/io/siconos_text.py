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
   - compressed sparse (``NM_SPARSE``): the origin of the matrix (1 triplet, 2 compressed
     columns, 3 compressed rows), then CSparse's own print of it: a banner line
     (``CSparse Version …``), a header (``[triplet:|csr:] n₀-by-n₁, nzmax: … nnz: …``), then
     each entry as ``i j : x`` (triplet) or, per column (row), ``col j : locations a to b``
     followed by its b − a + 1 entries ``i : x``. CSparse prints the entries with six
     significant digits (``%g``): the problem is the one of the rounded numbers, as Siconos
     itself reads it back;

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
import re
import zlib
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..base.outputs import atomic_output
from ..errors import InputError, ProblemFileError
from ..model.friction import FrictionContactProblem

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

SPARSE_ORIGINS = {1: "triplet", 2: "compressed columns", 3: "compressed rows"}
"""Origins of a compressed-sparse W read (Siconos' ``NSM_TRIPLET``, ``NSM_CSC``,
``NSM_CSR``); its fourth, ``NSM_HALF_TRIPLET``, is refused."""

BANNER_TOKENS = 40
"""Most words of CSparse's banner line searched for the header that follows it."""

LEGACY_FLAGS = ("0", "1")
"""The one number Siconos wrote after μ before 2010 (``isComplete``), skipped on reading."""


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


class _Numbers:
    """The white-space separated numbers of one file, taken in order, each checked and
    named in every error by its field and its position in the file."""

    def __init__(self, path: Path, text: str) -> None:
        self.path = path
        self.tokens = text.split()
        self.pos = 0

    def error(self, field: str, what: str, at: int | None = None) -> ProblemFileError:
        where = self.pos if at is None else at
        return ProblemFileError(f"{self.path}: {field} (number {where + 1} of the file): {what}")

    def take(self, field: str, count: int) -> list[str]:
        if count > len(self.tokens) - self.pos:
            raise self.error(field, f"the file ends after {len(self.tokens)} numbers, "
                                    f"{count} more expected here (truncated, or a count in the "
                                    "header is wrong)")
        out = self.tokens[self.pos:self.pos + count]
        self.pos += count
        return out

    def integer(self, field: str, low: int, high: int) -> int:
        token = self.take(field, 1)[0]
        try:
            value = int(token)
        except ValueError:
            raise self.error(field, f"{token!r} is not an integer", self.pos - 1) from None
        if not low <= value <= high:
            raise self.error(field, f"{value} is outside [{low}, {high}]", self.pos - 1)
        return value

    def integers(self, field: str, count: int, low: int, high: int) -> np.ndarray:
        start = self.pos
        tokens = self.take(field, count)
        try:
            values = np.array([int(t) for t in tokens], dtype=np.int64)
        except ValueError:
            bad = next(k for k, t in enumerate(tokens) if not t.lstrip("+-").isdigit())
            raise self.error(field, f"{tokens[bad]!r} is not an integer", start + bad) from None
        out = np.flatnonzero((values < low) | (values > high))
        if out.size:
            raise self.error(field, f"{values[out[0]]} is outside [{low}, {high}]",
                             start + int(out[0]))
        return values

    def floats(self, field: str, count: int) -> np.ndarray:
        start = self.pos
        tokens = self.take(field, count)
        try:
            values = np.array(tokens, dtype=float)
        except ValueError:
            bad = next(k for k, t in enumerate(tokens) if not _is_float(t))
            raise self.error(field, f"{tokens[bad]!r} is not a number", start + bad) from None
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise self.error(field, f"holds {bad.size} non-finite number(s) (NaN or "
                                    "infinity), the first here", start + int(bad[0]))
        return values

    def finish(self) -> None:
        left = len(self.tokens) - self.pos
        if left == 1 and self.tokens[-1] in LEGACY_FLAGS:
            return
        if left:
            raise self.error("after μ", f"{left} number(s) left over; a count in the file "
                                        "does not match its contents")


def _is_float(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def _dense(numbers: _Numbers, n0: int, n1: int) -> np.ndarray:
    numbers.integer("W's rows (dense)", n0, n0)
    numbers.integer("W's columns (dense)", n1, n1)
    return numbers.floats("W (dense, column by column)", n0 * n1).reshape(n1, n0).T


def _ends(numbers: _Numbers, field: str, count: int, size: int) -> np.ndarray:
    """Cumulated block sizes: increasing, ending at ``size``."""
    ends = numbers.integers(field, count, 1, size)
    if np.any(np.diff(ends) <= 0) or ends[-1] != size:
        raise numbers.error(field, f"must increase and end at {size}, got "
                                   f"{ends[:4].tolist()}…{ends[-1]}", numbers.pos - count)
    return ends


def _blocks(numbers: _Numbers, n0: int, n1: int) -> sp.csr_matrix:
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


def _block_values(numbers: _Numbers, tokens: list[str], first: np.ndarray,
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
        bad = next(k for k, t in enumerate(tokens) if not _is_float(t))
        raise numbers.error(field(bad), f"{tokens[bad]!r} is not a number", at + bad) from None
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise numbers.error(field(int(bad[0])), f"holds {bad.size} non-finite number(s) (NaN "
                                                "or infinity), the first here", at + int(bad[0]))
    return values


def _sparse(numbers: _Numbers, n0: int, n1: int) -> sp.csr_matrix:
    """A compressed-sparse W: its origin, then CSparse's print of it (see the module doc)."""
    origin = numbers.integer("W's sparse origin", 1, 4)
    if origin not in SPARSE_ORIGINS:
        raise numbers.error("W's sparse origin", f"{origin} (half triplet) is not read; "
                                                 "1 (triplet), 2 (compressed columns) and 3 "
                                                 "(compressed rows) are", numbers.pos - 1)
    field = "W's CSparse header"
    if numbers.take(field, 1)[0] != "CSparse":
        raise numbers.error(field, "expected CSparse's banner 'CSparse Version …'",
                            numbers.pos - 1)
    start = numbers.pos
    window = numbers.tokens[start:start + BANNER_TOKENS]
    at = next((k for k, t in enumerate(window) if re.fullmatch(r"\d+-by-\d+,", t)), None)
    if at is None:
        raise numbers.error(field, "no 'rows-by-columns,' header after the banner", start)
    numbers.pos = start + at
    rows, cols = (int(x) for x in numbers.take(field, 1)[0][:-1].split("-by-"))
    if (rows, cols) != (n0, n1):
        raise numbers.error(field, f"{rows}-by-{cols} is not W's {n0}-by-{n1}",
                            numbers.pos - 1)
    kind = {"triplet:": 1, "csr:": 3}.get(numbers.tokens[start + at - 1], 2) if at else 2
    if kind != origin:
        raise numbers.error(field, f"prints {SPARSE_ORIGINS[kind]}, the origin says "
                                   f"{SPARSE_ORIGINS[origin]}", numbers.pos - 1)
    _word(numbers, field, "nzmax:")
    numbers.integer("W's nzmax", 0, MAX_SIZE**2)
    _word(numbers, field, "nnz:")
    if kind == 1:
        nnz = numbers.integer("W's number of entries", 0, MAX_SIZE**2)
        at = numbers.pos
        cells = np.array(numbers.take("W's entries (i j : x)", 4 * nnz)).reshape(nnz, 4)
        where = at + 4 * np.arange(nnz)
        i, j, x = _entries(numbers, cells[:, [0, 2, 3]], where, n0, "W's entries (i j : x)",
                           column=(cells[:, 1], n1))
        return sp.csr_matrix(sp.coo_matrix((x, (i, j)), shape=(n0, n1)))  # duplicates add
    token = numbers.take("W's number of entries", 1)[0]
    if not token.endswith(",") or not token[:-1].isdigit():
        raise numbers.error("W's number of entries", f"{token!r} is not 'count,'",
                            numbers.pos - 1)
    _word(numbers, field, "1-norm:")
    numbers.take("W's 1-norm", 1)
    outer, inner, word = (n1, n0, "col") if kind == 2 else (n0, n1, "row")
    heads, counts = [], []  # where each column's entries start, and how many
    tokens, end = numbers.tokens, 0
    for j in range(outer):
        at = numbers.pos
        head = numbers.take(f"W's {word} {j}", 7)
        first, last = head[4], head[6]
        if head[:4] != [word, str(j), ":", "locations"] or head[5] != "to" \
                or not first.isdigit() or not (last.isdigit() or last == "-1"):
            raise numbers.error(f"W's {word} {j}", f"expected '{word} {j} : locations a to "
                                                   f"b', got {' '.join(head)!r}", at)
        if int(first) != end or int(last) < end - 1:
            raise numbers.error(f"W's {word} {j}", f"locations {first} to {last} do not "
                                                   f"follow entry {end - 1}", at + 4)
        end = int(last) + 1
        heads.append(numbers.pos)
        counts.append(end - int(first))
        numbers.take(f"W's {word} {j} entries", 3 * counts[-1])
    counts_a = np.array(counts, dtype=np.int64)
    offsets = np.arange(int(counts_a.sum())) - np.repeat(np.cumsum(counts_a) - counts_a,
                                                         counts_a)
    where = np.repeat(np.array(heads, dtype=np.int64), counts_a) + 3 * offsets
    base = heads[0] if heads else 0  # the entries' tokens, from the first column's on
    cells = np.array(tokens[base:numbers.pos] or [""])[where[:, None] - base + np.arange(3)]
    index, _, values = _entries(numbers, cells, where, inner,
                                f"W's entries ({SPARSE_ORIGINS[kind]})")
    pointers = np.r_[0, np.cumsum(counts_a)]
    W = (sp.csc_matrix if kind == 2 else sp.csr_matrix)((values, index, pointers),
                                                         shape=(n0, n1))
    W.sum_duplicates()
    return sp.csr_matrix(W)


def _word(numbers: _Numbers, field: str, word: str) -> None:
    if numbers.take(field, 1)[0] != word:
        raise numbers.error(field, f"expected {word!r}", numbers.pos - 1)


def _entries(numbers: _Numbers, cells: np.ndarray, where: np.ndarray, size: int, field: str,
             column: tuple[np.ndarray, int] | None = None
             ) -> tuple[np.ndarray, np.ndarray | None, np.ndarray]:
    """The index, ':' and value of each entry (rows of ``cells``, the first at file position
    ``where``; a triplet's column index one position after its row and ``column`` = (those
    tokens, their bound)), checked: indices in [0, size), ':' in place, values finite."""
    cells = cells.astype(str)
    shift = 1 if column is None else 2  # positions of ':' and x after the index
    bad = np.flatnonzero(cells[:, 1] != ":")
    if bad.size:
        raise numbers.error(field, f"expected ':', got {cells[bad[0], 1]!r}",
                            int(where[bad[0]]) + shift)
    index = _indices(numbers, cells[:, 0], where, size, field)
    other = None if column is None else _indices(numbers, column[0].astype(str), where + 1,
                                                 column[1], field)
    try:
        values = cells[:, 2].astype(float)
    except ValueError:
        k = next(k for k, t in enumerate(cells[:, 2]) if not _is_float(str(t)))
        raise numbers.error(field, f"{cells[k, 2]!r} is not a number",
                            int(where[k]) + shift + 1) from None
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise numbers.error(field, f"holds {bad.size} non-finite number(s) (NaN or "
                                   "infinity), the first here", int(where[bad[0]]) + shift + 1)
    return index, other, values


def _indices(numbers: _Numbers, tokens: np.ndarray, where: np.ndarray, size: int,
             field: str) -> np.ndarray:
    """Integers in [0, size), the k-th token at file position ``where[k]``."""
    ok = np.char.isdigit(tokens) if tokens.size else np.ones(0, dtype=bool)
    if not ok.all():
        k = int(np.flatnonzero(~ok)[0])
        raise numbers.error(field, f"{tokens[k]!r} is not an index", int(where[k]))
    values = tokens.astype(np.int64)
    bad = np.flatnonzero(values >= size)
    if bad.size:
        raise numbers.error(field, f"{values[bad[0]]} is outside [0, {size - 1}]",
                            int(where[bad[0]]))
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
        or more than :data:`MAX_TEXT_BYTES` of text. The message names the file, the field
        and the position of the number.
    """
    path = Path(path)
    numbers = _Numbers(path, _text(path))
    if not numbers.tokens:
        raise ProblemFileError(f"{path}: empty; not a Siconos text problem file")
    d = numbers.integer("d, the dimension of a contact", 2, 3)
    m = numbers.integer("the number of contacts", 1, MAX_SIZE // d)
    storage = numbers.integer("W's storage", 0, 2)
    n0 = numbers.integer("W's rows", d * m, d * m)
    n1 = numbers.integer("W's columns", d * m, d * m)
    W = (_dense, _blocks, _sparse)[storage](numbers, n0, n1)
    q = numbers.floats("q", n1)
    at = numbers.pos
    mu = numbers.floats("μ", m)
    if np.any(mu < 0):
        raise numbers.error("μ", f"friction coefficients must be ≥ 0, found {mu.min()}",
                            at + int(np.argmin(mu)))
    numbers.finish()
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
