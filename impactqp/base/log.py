"""impactqp's logging: every module logs under the ``"impactqp"`` logger, and ``verbose=``
switches a stderr handler on for one call.

What is logged: backend attempts, fallbacks, polishing rounds and certificate verdicts at
DEBUG; refusals (a backend not installed or unsuitable, a compiled path that declines) at
INFO. The library adds no handler of its own beyond a :class:`logging.NullHandler`: an
application configures ``logging.getLogger("impactqp")`` as it likes.
"""

from __future__ import annotations

import logging
from collections.abc import Iterator
from contextlib import contextmanager

from ..errors import InputError

ROOT = logging.getLogger("impactqp")
ROOT.addHandler(logging.NullHandler())

LEVELS = (None, logging.INFO, logging.DEBUG)
"""By ``verbose``: False/0 silent, True/1 refusals and fallbacks, 2 every attempt."""


def verbose_level(verbose: object) -> int | None:
    """The logging level of a ``verbose`` argument (None: nothing extra).

    Raises
    ------
    InputError
        For anything but a bool or 0, 1, 2.
    """
    if isinstance(verbose, (bool, int)) and 0 <= verbose <= 2:
        return LEVELS[int(verbose)]
    raise InputError(f"verbose must be True/False or 0, 1, 2, got {verbose!r}")


@contextmanager
def verbosity(verbose: object) -> Iterator[None]:
    """While it lasts, impactqp's records at the level of ``verbose`` go to stderr (the
    logger's level is lowered only as needed and restored after)."""
    level = verbose_level(verbose)
    if level is None:
        yield
        return
    handler = logging.StreamHandler()
    handler.setLevel(level)
    handler.setFormatter(logging.Formatter("impactqp: %(levelname)s %(name)s: %(message)s"))
    before = ROOT.level
    ROOT.addHandler(handler)
    if before == logging.NOTSET or before > level:
        ROOT.setLevel(level)
    try:
        yield
    finally:
        ROOT.removeHandler(handler)
        ROOT.setLevel(before)
