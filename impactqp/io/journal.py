"""A journal of records, one JSON object a line (JSON Lines), appended as the records arrive.

A run that writes its records here can be stopped at any moment and started again: the
records already written are read back (:meth:`Journal.records`) and their work skipped. A
writer killed in the middle of a line leaves a last line without its newline; the first
record appended after opening the journal again replaces that fragment (the record it began
is done again), while a damaged line
before the last one is an error that names it: something other than this writer touched
the file.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from ..base.outputs import output_file
from ..errors import ProblemFileError

__all__ = ["Journal"]


class Journal:
    """Records of a run in a JSON Lines file, read when opened and appended one by one.

    Parameters
    ----------
    path : str or Path
        The file; created (with its folder) on the first record when missing.

    Raises
    ------
    InputError
        ``path`` exists and is not a regular file.
    ProblemFileError
        A line before the last one is not a JSON object (the message names the line).
    """

    def __init__(self, path: str | Path) -> None:
        self.path = output_file(path)
        self._records, self._complete = _read(self.path)

    def records(self) -> list[dict[str, Any]]:
        """The records written so far (read back when opened, then each appended one)."""
        return list(self._records)

    def append(self, record: dict[str, Any]) -> None:
        """Write ``record`` as one line, flushed to the operating system at once (a crash of
        this process loses nothing written before it). Not synced to the disk: a record a
        crash of the machine loses is only solved again (a sync cost 3.7 ms a record)."""
        line = json.dumps(record, allow_nan=False, separators=(",", ":")) + "\n"
        self.path.parent.mkdir(parents=True, exist_ok=True)
        with self.path.open("a+b") as fh:
            if self._complete is not None:  # cut a fragment a killed writer left
                fh.truncate(self._complete)
                self._complete = None
            fh.write(line.encode("utf-8"))
            fh.flush()
        self._records.append(record)


def _read(path: Path) -> tuple[list[dict[str, Any]], int | None]:
    """The records of ``path`` and, when its last line is a fragment, the byte length of the
    complete lines before it (None when the file ends with a whole line or is missing)."""
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        return [], None
    lines = data.split(b"\n")
    tail = lines.pop()  # after the last newline: b"" when the file ends with one
    records = []
    for number, line in enumerate(lines, start=1):
        record = _record(line)
        if record is None:
            raise ProblemFileError(f"{path}: line {number} is not a JSON object "
                                   "(only a last line cut short is tolerated)")
        records.append(record)
    # a last line without its newline was cut short by a killed writer (even one that
    # parses: the next record must start a line of its own)
    return records, (len(data) - len(tail)) if tail else None


def _record(line: bytes) -> dict[str, Any] | None:
    try:
        value = json.loads(line)
    except (ValueError, UnicodeDecodeError):
        return None
    return value if isinstance(value, dict) else None
