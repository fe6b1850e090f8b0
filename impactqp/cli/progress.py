"""A heartbeat for long steps of the command line, without any extra dependency.

Nothing is printed for steps that finish within ``after`` seconds, so quick commands stay
quiet; a long step (a large problem file) says on stderr what it is doing and for how long,
when stderr is a terminal (a log file or a pipe gets no heartbeat: :func:`on_terminal`).
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import IO


def on_terminal(stream: IO[str] | None = None) -> bool:
    """True when ``stream`` (default ``sys.stderr`` at call time) is a terminal: progress is
    shown there only, never written into a log file or a pipe."""
    out = sys.stderr if stream is None else stream
    try:
        return bool(out.isatty())
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


@contextmanager
def progress(message: str, *, after: float = 2.0, every: float = 5.0,
             stream: IO[str] | None = None) -> Iterator[None]:
    """Report ``impactqp: <message>… <t> s`` on stderr while the ``with`` block runs.

    Parameters
    ----------
    message : str
        What the block does, e.g. ``"checking u⁺ ∈ S (n = 3000)"``.
    after : float
        Seconds of silence before the first report.
    every : float
        Seconds between later reports.
    stream : text stream, optional
        Where to report (default ``sys.stderr`` at call time, and then only when it is a
        terminal); a stream given is reported to whatever it is.
    """
    if stream is None and not on_terminal():
        yield
        return
    out = sys.stderr if stream is None else stream
    done = threading.Event()
    start = time.monotonic()

    def beat() -> None:
        wait = after
        while not done.wait(wait):
            print(f"impactqp: {message}… {time.monotonic() - start:.0f} s", file=out, flush=True)
            wait = every

    thread = threading.Thread(target=beat, daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        thread.join()
