"""A heartbeat for long steps of the command line, without any extra dependency.

Nothing is printed for steps that finish within ``after`` seconds, so quick commands stay
quiet; a long step (a large problem file) says on stderr what it is doing and for how long.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import IO


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
        Where to report (default ``sys.stderr`` at call time).
    """
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
