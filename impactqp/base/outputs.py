"""Where and how impactqp writes.

Only to regular files, so that an output path naming a FIFO, a device or a directory is
refused at once instead of blocking or failing half-way (:func:`output_file`); and every
file atomically (:func:`atomic_output`): the writer fills a temporary file in the target's
folder, which replaces the target by one rename only once it is complete, so a writer that
fails or is killed half-way leaves the previous file as it was.
"""

from __future__ import annotations

import os
import secrets
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from ..errors import InputError

NEW_FILE_MODE = 0o666
"""Permissions asked for a new file, before the process's umask (as ``open(path, "w")``)."""


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


def _temporary_beside(target: Path) -> Path:
    """A new, empty file in ``target``'s folder, hidden, ending in ``target``'s suffix (writers
    that choose their format by the suffix see the right one), with the permissions a new
    file gets from the umask, or those of the existing target."""
    while True:
        temp = target.with_name(f".{target.stem}.{secrets.token_hex(4)}.part{target.suffix}")
        try:
            fd = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, NEW_FILE_MODE)
        except FileExistsError:
            continue
        except OSError as exc:
            raise InputError(f"cannot write {target}: {exc.strerror or exc}") from None
        try:
            if target.exists():
                os.fchmod(fd, stat.S_IMODE(target.stat().st_mode))
        finally:
            os.close(fd)
        return temp


def _flush_to_disk(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """Write ``path`` all or nothing: yield a temporary path beside it for the writer to fill;
    when the block ends normally the temporary file is flushed to disk and renamed onto
    ``path`` (``os.replace``, atomic on one filesystem), when it raises (or is interrupted)
    the temporary file is removed and ``path`` is left as it was.

    A symbolic link is followed: the file it names is replaced, the link stays.

    Parameters
    ----------
    path : str or Path
        The file to write: new, or an existing regular file (:func:`output_file`).

    Yields
    ------
    Path
        The temporary file (empty, same folder and suffix) to write instead of ``path``.

    Raises
    ------
    InputError
        ``path`` exists and is not a regular file, or its folder cannot be written.
    """
    target = output_file(path)
    if target.is_symlink():
        target = Path(os.path.realpath(target))
    temp = _temporary_beside(target)
    try:
        yield temp
        _flush_to_disk(temp)
        os.replace(temp, target)
    except BaseException:
        temp.unlink(missing_ok=True)
        raise
