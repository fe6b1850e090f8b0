"""Where impactqp writes: only to regular files, so that an output path naming a FIFO, a
device or a directory is refused at once instead of blocking or failing half-way."""

from __future__ import annotations

import stat
from pathlib import Path

from ..errors import InputError


def output_file(path: str | Path) -> Path:
    """``path`` as a Path that may be written: new, or an existing regular file.

    Raises
    ------
    InputError
        When it exists and is not a regular file (a FIFO would block the writer forever).
    """
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        return path
    except OSError as exc:
        raise InputError(f"cannot write {path}: {exc.strerror or exc}") from None
    if not stat.S_ISREG(mode):
        raise InputError(f"cannot write {path}: it exists and is not a regular file "
                         "(a FIFO, a device or a directory)")
    return path
