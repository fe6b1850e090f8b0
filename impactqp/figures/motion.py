"""Pictures of a simulated motion (docs/theory.md §14): energy and positions over time, and an
animation of Newton's cradle.

matplotlib is an optional extra (``pip install 'impactqp[plot]'``), imported inside the
functions only. Figures are bare :class:`matplotlib.figure.Figure` objects (no pyplot), so
they render headless; an animation is written as GIF (Pillow, which matplotlib brings) or MP4
(ffmpeg).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..base.arrays import as_count, as_real
from ..errors import InputError, OptionalDependencyError
from ..simulation.trajectory import Trajectory
from .plots import DPI, figure_format, new_figure, save_figure

MOVIE_FORMATS = (".gif", ".mp4")


def _check(trajectory: Any) -> Trajectory:
    if not isinstance(trajectory, Trajectory):
        raise InputError(f"trajectory must be an impactqp Trajectory (from iq.simulate), got "
                         f"{type(trajectory).__name__}")
    return trajectory


def _impact_marks(ax: Any, trajectory: Trajectory) -> None:
    times = np.unique(trajectory.impact_times)
    if times.size and times.size <= 200 and trajectory.scheme == "event-driven":
        for t in times:
            ax.axvline(t, color="0.8", lw=0.6, zorder=0)


def plot_energy(trajectory: Trajectory, path: str | Path, title: str = "") -> Path:
    """Write kinetic, potential and total energy over time (PNG or SVG); impacts of an
    event-driven run are marked by thin vertical lines."""
    tr = _check(trajectory)
    figure_format(path)
    fig = new_figure(6.4, 3.6)
    ax = fig.add_subplot()
    _impact_marks(ax, tr)
    ax.plot(tr.t, tr.kinetic_energy, lw=1.0, label="kinetic T")
    ax.plot(tr.t, tr.potential_energy, lw=1.0, label="potential V")
    ax.plot(tr.t, tr.total_energy, lw=1.6, color="black", label="total T + V")
    ax.set_xlabel("t")
    ax.set_ylabel("energy")
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(title or f"{tr.scheme}, {tr.law!r}: energy", fontsize=10)
    return save_figure(fig, path)


def plot_positions(trajectory: Trajectory, path: str | Path, title: str = "",
                   dofs: Any = None) -> Path:
    """Write the positions q_i(t) of the chosen degrees of freedom (all, up to 12, when
    omitted) over time (PNG or SVG)."""
    tr = _check(trajectory)
    figure_format(path)
    n = tr.q.shape[1]
    chosen = np.arange(min(n, 12)) if dofs is None else np.atleast_1d(np.asarray(dofs))
    if chosen.dtype.kind not in "iu" or chosen.size == 0 or chosen.min() < 0 or \
            chosen.max() >= n:
        raise InputError(f"dofs must be indices in [0, {n - 1}], got {dofs!r}")
    fig = new_figure(6.4, 3.6)
    ax = fig.add_subplot()
    _impact_marks(ax, tr)
    for i in chosen:
        ax.plot(tr.t, tr.q[:, i], lw=1.1, label=f"q{i + 1}")
    ax.set_xlabel("t")
    ax.set_ylabel("position")
    ax.legend(loc="upper right", fontsize=8, ncol=2)
    ax.set_title(title or f"{tr.scheme}, {tr.law!r}: positions", fontsize=10)
    return save_figure(fig, path)


def cradle_frames(trajectory: Trajectory, frames: int) -> tuple[np.ndarray, np.ndarray]:
    """(times, positions): the trajectory sampled at ``frames`` equally spaced times (records
    at an impact share their time; positions are continuous there)."""
    tr = _check(trajectory)
    times = np.linspace(tr.t[0], tr.t[-1], frames)
    Q = np.column_stack([np.interp(times, tr.t, tr.q[:, i]) for i in range(tr.q.shape[1])])
    return times, Q


def animate_cradle(trajectory: Trajectory, path: str | Path, *, length: float = 1.0,
                   radius: float = 0.05, frames: int = 120, fps: int = 24,
                   size: float = 3.2) -> Path:
    """Write an animation of a cradle run (GIF through Pillow, or MP4 through ffmpeg).

    Parameters
    ----------
    trajectory : Trajectory
        A run of :func:`impactqp.cradle_system` (qᵢ the horizontal displacement of ball i).
    path : str or Path
        ``.gif`` or ``.mp4``.
    length, radius : float
        Pendulum length and ball radius of the drawing (pivots one diameter apart).
    frames, fps : int
        Number of frames (equally spaced in time) and frames per second.
    size : float
        Width of the picture in inches.

    Raises
    ------
    InputError
        Another suffix, or bad numbers.
    OptionalDependencyError
        matplotlib is missing.
    """
    tr = _check(trajectory)
    suffix = Path(path).suffix.lower()
    if suffix not in MOVIE_FORMATS:
        raise InputError(f"animation file must end in one of {MOVIE_FORMATS}, got "
                         f"{Path(path).name!r}")
    length = as_real("length", length, positive=True)
    radius = as_real("radius", radius, positive=True)
    frames, fps = as_count("frames", frames, minimum=2), as_count("fps", fps, minimum=1)
    fig = new_figure(size, 0.75 * size)
    try:
        from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter
        from matplotlib.patches import Circle
    except ImportError:
        raise OptionalDependencyError("animations need matplotlib: pip install "
                                      "'impactqp[plot]'") from None
    times, Q = cradle_frames(tr, frames)
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
    clock = ax.text(0.02, 0.02, "", transform=ax.transAxes, fontsize=8, va="bottom")

    def draw(k: int) -> list:
        x = pivots + Q[k]
        y = -np.sqrt(np.maximum(length**2 - Q[k] ** 2, 0.0))
        for i in range(n):
            strings[i].set_data([pivots[i], x[i]], [0.0, y[i]])
            balls[i].center = (x[i], y[i])
        clock.set_text(f"t = {times[k]:.2f}")
        return strings + balls + [clock]

    movie = FuncAnimation(fig, draw, frames=frames, interval=1000.0 / fps, blit=False)
    writer = PillowWriter(fps=fps) if suffix == ".gif" else FFMpegWriter(fps=fps)
    movie.save(str(path), writer=writer, dpi=DPI)
    return Path(path)
