"""Pictures of a simulated motion (docs/theory.md §14): energy and positions over time, and an
animation of the balls; what :meth:`Trajectory.plot` and :meth:`Trajectory.animate` draw.

Each drawing returns the matplotlib object (a pyplot-free Figure, or a FuncAnimation) and
writes it when given a path (PNG, SVG or PDF; GIF through Pillow or MP4 through ffmpeg).
matplotlib is an optional extra (``pip install 'impactqp[plot]'``), imported only here.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..base.arrays import as_count, as_real
from ..base.figure import DPI, figure_format, new_figure, save_figure
from ..base.outputs import atomic_output
from ..errors import InputError, OptionalDependencyError

KINDS = ("positions", "energy")
MOVIE_FORMATS = (".gif", ".mp4")
MAX_LINES = 12
"""Degrees of freedom drawn by default (the first ones)."""


def _impact_marks(ax: Any, trajectory: Any) -> None:
    times = np.unique(trajectory.impact_times)
    if times.size and times.size <= 200 and trajectory.scheme == "event-driven":
        for t in times:
            ax.axvline(t, color="0.8", lw=0.6, zorder=0)


def _chosen(dofs: Any, n: int) -> np.ndarray:
    chosen = np.arange(min(n, MAX_LINES)) if dofs is None else np.atleast_1d(np.asarray(dofs))
    if chosen.dtype.kind not in "iu" or chosen.size == 0 or chosen.min() < 0 or \
            chosen.max() >= n:
        raise InputError(f"dofs must be indices in [0, {n - 1}], got {dofs!r}")
    return chosen


def plot(trajectory: Any, kind: str = "positions", path: str | Path | None = None, *,
         title: str = "", dofs: Any = None) -> Any:
    """Positions qᵢ(t) or the energies T, V and T + V over time; impacts of an event-driven
    run are marked by thin vertical lines.

    Parameters
    ----------
    trajectory : Trajectory
    kind : {"positions", "energy"}
    path : str or Path, optional
        Where to write the figure (``.png``, ``.svg`` or ``.pdf``).
    title : str
        Axes title (default: scheme, law and kind).
    dofs : int or sequence of int, optional
        The degrees of freedom drawn (``"positions"``; default the first 12).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InputError
        Unknown ``kind``, bad ``dofs`` or an unknown file suffix.
    OptionalDependencyError
        matplotlib is missing.
    """
    if kind not in KINDS:
        raise InputError(f"kind must be one of {KINDS}, got {kind!r}")
    if path is not None:
        figure_format(path)
    tr = trajectory
    chosen = _chosen(dofs, tr.q.shape[1]) if kind == "positions" else None
    fig = new_figure(6.4, 3.6)
    ax = fig.add_subplot()
    _impact_marks(ax, tr)
    if kind == "energy":
        ax.plot(tr.t, tr.kinetic_energy, lw=1.0, label="kinetic T")
        ax.plot(tr.t, tr.potential_energy, lw=1.0, label="potential V")
        ax.plot(tr.t, tr.total_energy, lw=1.6, color="black", label="total T + V")
        ax.set_ylabel("energy")
        ax.legend(loc="upper right", fontsize=8)
    else:
        for i in chosen:
            ax.plot(tr.t, tr.q[:, i], lw=1.1, label=f"q{i + 1}")
        ax.set_ylabel("position")
        ax.legend(loc="upper right", fontsize=8, ncol=2)
    ax.set_xlabel("t")
    ax.set_title(title or f"{tr.scheme}, {tr.law!r}: {kind}", fontsize=10)
    if path is not None:
        save_figure(fig, path)
    return fig


def frames_of(trajectory: Any, frames: int) -> tuple[np.ndarray, np.ndarray]:
    """(times, positions): the trajectory sampled at ``frames`` equally spaced times (records
    at an impact share their time; positions are continuous there)."""
    tr = trajectory
    times = np.linspace(tr.t[0], tr.t[-1], frames)
    Q = np.column_stack([np.interp(times, tr.t, tr.q[:, i]) for i in range(tr.q.shape[1])])
    return times, Q


def animate(trajectory: Any, path: str | Path | None = None, *, length: float = 1.0,
            radius: float = 0.05, frames: int = 120, fps: int = 24, size: float = 3.2) -> Any:
    """An animation of a run of balls on pendulums
    (:func:`impactqp.simulation.cradle_system`: qᵢ the horizontal displacement of ball i),
    written when given a path.

    Parameters
    ----------
    trajectory : Trajectory
    path : str or Path, optional
        ``.gif`` (Pillow) or ``.mp4`` (ffmpeg).
    length, radius : float
        Pendulum length and ball radius of the drawing (pivots one diameter apart).
    frames, fps : int
        Number of frames (equally spaced in time) and frames per second.
    size : float
        Width of the picture in inches.

    Returns
    -------
    matplotlib.animation.FuncAnimation

    Raises
    ------
    InputError
        Another suffix, or bad numbers.
    OptionalDependencyError
        matplotlib is missing.
    """
    suffix = None if path is None else Path(path).suffix.lower()
    if suffix is not None and suffix not in MOVIE_FORMATS:
        raise InputError(f"animation file must end in one of {MOVIE_FORMATS}, got "
                         f"{Path(path).name!r}")
    length = as_real("length", length, positive=True)
    radius = as_real("radius", radius, positive=True)
    size = as_real("size", size, positive=True)
    frames, fps = as_count("frames", frames, minimum=2), as_count("fps", fps, minimum=1)
    fig = new_figure(size, 0.75 * size)
    try:
        from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter
        from matplotlib.patches import Circle
    except ImportError:
        raise OptionalDependencyError("animations need matplotlib: pip install "
                                      "'impactqp[plot]'") from None
    times, Q = frames_of(trajectory, frames)
    n = Q.shape[1]
    pivots = 2.0 * radius * (np.arange(n) - (n - 1) / 2.0)
    ax = fig.add_subplot()
    reach = max(np.abs(Q).max(), radius) + pivots[-1] + 2 * radius
    ax.set_xlim(-reach, reach)
    ax.set_ylim(-length - 2 * radius, 0.1 * length)
    ax.set_aspect("equal")
    ax.axis("off")
    ax.plot([pivots[0] - radius, pivots[-1] + radius], [0, 0], color="0.3", lw=2)
    strings = [ax.plot([], [], color="0.4", lw=0.8)[0] for _ in range(n)]
    balls = [ax.add_patch(Circle((0, 0), radius, fc="tab:blue", ec="black", lw=0.6))
             for _ in range(n)]
    # the clock sits above the bar, where no ball ever swings
    clock = ax.text(0.02, 0.98, "", transform=ax.transAxes, fontsize=8, va="top")

    def draw(k: int) -> list:
        x = pivots + Q[k]
        y = -np.sqrt(np.maximum(length**2 - Q[k] ** 2, 0.0))
        for i in range(n):
            strings[i].set_data([pivots[i], x[i]], [0.0, y[i]])
            balls[i].center = (x[i], y[i])
        clock.set_text(f"t = {times[k]:.2f}")
        return strings + balls + [clock]

    movie = FuncAnimation(fig, draw, frames=frames, interval=1000.0 / fps, blit=False)
    if path is not None:
        writer = PillowWriter(fps=fps) if suffix == ".gif" else FFMpegWriter(fps=fps)
        with atomic_output(path) as temp:
            movie.save(str(temp), writer=writer, dpi=DPI)
    return movie
