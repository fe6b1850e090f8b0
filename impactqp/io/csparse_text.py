"""W in Siconos' compressed-sparse storage (``NM_SPARSE``, storage 2 of its text files):
the matrix's origin, then CSparse's own print of it (the layout: :mod:`.siconos_text`)."""

from __future__ import annotations

import re

import numpy as np
import scipy.sparse as sp

from .text_numbers import TextNumbers, is_float

MAX_ENTRIES = 10**12
"""Largest entry count accepted in a header (the size check of W comes first)."""

SPARSE_ORIGINS = {1: "triplet", 2: "compressed columns", 3: "compressed rows"}
"""Origins of a compressed-sparse W read (Siconos' ``NSM_TRIPLET``, ``NSM_CSC``,
``NSM_CSR``); its fourth, ``NSM_HALF_TRIPLET``, is refused."""

BANNER_TOKENS = 40
"""Most words of CSparse's banner line searched for the header that follows it."""


def read_compressed_sparse(numbers: TextNumbers, n0: int, n1: int) -> sp.csr_matrix:
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
    numbers.integer("W's nzmax", 0, MAX_ENTRIES)
    _word(numbers, field, "nnz:")
    if kind == 1:
        nnz = numbers.integer("W's number of entries", 0, MAX_ENTRIES)
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


def _word(numbers: TextNumbers, field: str, word: str) -> None:
    if numbers.take(field, 1)[0] != word:
        raise numbers.error(field, f"expected {word!r}", numbers.pos - 1)


def _entries(numbers: TextNumbers, cells: np.ndarray, where: np.ndarray, size: int, field: str,
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
        k = next(k for k, t in enumerate(cells[:, 2]) if not is_float(str(t)))
        raise numbers.error(field, f"{cells[k, 2]!r} is not a number",
                            int(where[k]) + shift + 1) from None
    bad = np.flatnonzero(~np.isfinite(values))
    if bad.size:
        raise numbers.error(field, f"holds {bad.size} non-finite number(s) (NaN or "
                                   "infinity), the first here", int(where[bad[0]]) + shift + 1)
    return index, other, values


def _indices(numbers: TextNumbers, tokens: np.ndarray, where: np.ndarray, size: int,
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
