"""Reader of the Siconos LCP test files kept in tests/data/siconos-lcp (source, license and
format: the README there)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent / "data" / "siconos-lcp"


def _tokens(path: Path) -> list[str]:
    return path.read_text().split()


def read_lcp(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Return (M, q) of one file; dense (storage 0) or sparse-block (storage 1)."""
    tok = _tokens(path)
    n, storage = int(tok[0]), int(tok[1])
    pos = 4  # n, storage, size0, size1
    if storage == 0:
        r, c = int(tok[pos]), int(tok[pos + 1])
        pos += 2
        M = np.array(tok[pos:pos + r * c], dtype=float).reshape(c, r).T  # column-major
        pos += r * c
    else:
        nbblock, nb0, nb1 = (int(t) for t in tok[pos:pos + 3])
        pos += 3
        rows_end = [int(t) for t in tok[pos:pos + nb0]]
        pos += nb0
        cols_end = [int(t) for t in tok[pos:pos + nb1]]
        pos += nb1
        filled1, filled2 = int(tok[pos]), int(tok[pos + 1])
        pos += 2
        rowptr = [int(t) for t in tok[pos:pos + filled1]]
        pos += filled1
        colidx = [int(t) for t in tok[pos:pos + filled2]]
        pos += filled2
        M = np.zeros((rows_end[-1], cols_end[-1]))
        starts_r, starts_c = [0] + rows_end[:-1], [0] + cols_end[:-1]
        for bi in range(nb0):
            for k in range(rowptr[bi], rowptr[bi + 1]):
                bj = colidx[k]
                pos += 1  # the block's own number
                h, w = rows_end[bi] - starts_r[bi], cols_end[bj] - starts_c[bj]
                block = np.array(tok[pos:pos + h * w], dtype=float).reshape(w, h).T
                pos += h * w
                M[starts_r[bi]:rows_end[bi], starts_c[bj]:cols_end[bj]] = block
        assert nbblock == filled2
    q = np.array(tok[pos:pos + n], dtype=float)
    return M, q


def all_files() -> list[Path]:
    return sorted(DATA.glob("*.dat"))
