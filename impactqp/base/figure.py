"""The figure plumbing every picture of impactqp shares: a pyplot-free matplotlib Figure, the
output format from a file's suffix, and saving without time stamps.

matplotlib is an optional extra (``pip install 'impactqp[plot]'``), imported only when a
figure is made. Figures are bare :class:`matplotlib.figure.Figure` objects (no pyplot, no
global state), so they render headless.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import InputError, OptionalDependencyError
from .outputs import atomic_output

FORMATS = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
DPI = 100

#: metadata keys that would make the output differ from run to run
_NO_DATES = {"png": {"Software": None}, "svg": {"Date": None},
             "pdf": {"CreationDate": None, "ModDate": None}}


def new_figure(width: float = 6.4, height: float | None = None) -> Any:
    """A pyplot-free matplotlib Figure (square unless ``height`` is given), or a clear error
    naming the extra to install."""
    try:
        from matplotlib.figure import Figure
    except ImportError:
        raise OptionalDependencyError("figures need matplotlib: pip install 'impactqp[plot]'") \
            from None
    return Figure(figsize=(width, width if height is None else height), dpi=DPI,
                  layout="constrained")


def figure_format(path: str | Path) -> str:
    """The figure format of an output path, from its suffix.

    Parameters
    ----------
    path : str or Path
        Output file.

    Returns
    -------
    str
        ``"png"``, ``"svg"`` or ``"pdf"``.

    Raises
    ------
    InputError
        For any other suffix.
    """
    fmt = FORMATS.get(Path(path).suffix.lower())
    if fmt is None:
        raise InputError(f"figure file must end in one of {sorted(FORMATS)}, got "
                         f"{Path(path).name!r}")
    return fmt


def save_figure(fig: Any, path: str | Path) -> Path:
    """Write ``fig`` in the format of the suffix of ``path``, without time stamps."""
    fmt = figure_format(path)
    with atomic_output(path) as temp:
        fig.savefig(temp, format=fmt, metadata=_NO_DATES[fmt])
    return Path(path)
