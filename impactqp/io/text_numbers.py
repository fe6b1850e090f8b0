"""The numbers of a text file of a problem, taken in order, each checked and named in every
error by its field and its position in the file (:mod:`.siconos_text`, :mod:`.csparse_text`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..errors import ProblemFileError

LEGACY_FLAGS = ("0", "1")
"""The one number Siconos wrote after μ before 2010 (``isComplete``), skipped on reading."""


class TextNumbers:
    """The white-space separated numbers of one file, taken in order, each checked and
    named in every error by its field and its position in the file."""

    def __init__(self, path: Path, text: str) -> None:
        self.path = path
        self.tokens = text.split()
        self.pos = 0
        if "_" in text:  # Python's int() and float() take '1_0' as 10; C's readers do not
            bad = next(k for k, t in enumerate(self.tokens) if "_" in t)
            raise self.error("a number", f"{self.tokens[bad]!r} is not a number ('_' is not "
                                         "a digit)", bad)

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
            bad = next(k for k, t in enumerate(tokens) if not is_float(t))
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


def is_float(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True
