"""Pictures of a simulated motion (docs/theory.md §14): coordinates, velocities, energies,
impulses and contact states over time, and an animation of the bodies the builders know;
what :meth:`Trajectory.plot` and :meth:`Trajectory.animate` draw.

Coordinates are drawn by kind, translations and rotations on axes of their own, each axis
labelled with the unit the system gives (:mod:`impactqp.simulation.coordinates`). Each
drawing returns the matplotlib object (a pyplot-free Figure, or a FuncAnimation) and writes
it when given a path (PNG, SVG or PDF; GIF through Pillow or MP4 through ffmpeg).
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
from .contact_states import contact_states
from .coordinates import Coordinate
from .scenes import draw_scene

KINDS = ("positions", "velocities", "energy", "impulses", "contacts")
"""What :func:`plot` draws over time."""
MOVIE_FORMATS = (".gif", ".mp4")
MAX_LINES = 12
"""Degrees of freedom drawn by default (the first ones)."""
AXIS_NAMES = {"positions": {"translation": "position", "rotation": "angle",
                            "generalized": "coordinate"},
              "velocities": {"translation": "velocity", "rotation": "angular velocity",
                             "generalized": "velocity"}}
"""The y label of each kind of coordinate, for positions and for velocities."""
STATE_COLORS = {"open": "0.85", "closed": "tab:blue", "stick": "tab:green",
                "slide": "tab:red"}
"""Colours of the contact states of :func:`plot` with ``kind="contacts"``."""


def _impact_marks(ax: Any, trajectory: Any) -> None:
    times = np.unique(trajectory.impact_times)
    if times.size and times.size <= 200 and trajectory.scheme == "event-driven":
        for t in times:
            ax.axvline(t, color="0.8", lw=0.6, zorder=0)


def chosen_dofs(coordinates: tuple[Coordinate, ...], dofs: Any) -> list[int]:
    """0-based column indices of the coordinates chosen by ``dofs``.

    Parameters
    ----------
    coordinates : tuple of Coordinate
        The system's.
    dofs : None, int, str or sequence of int or str
        Names (``"x"``, ``"φ"``, ``"q2"``) or 1-based numbers, as in the labels; None picks
        the first 12.

    Raises
    ------
    InputError
        An unknown name, a number outside 1 … n, or nothing chosen.
    """
    n = len(coordinates)
    if dofs is None:
        return list(range(min(n, MAX_LINES)))
    names = {c.name: i for i, c in enumerate(coordinates)}
    picks = [dofs] if isinstance(dofs, (str, int, np.integer)) else list(np.ravel(dofs)) \
        if isinstance(dofs, np.ndarray) else list(dofs)
    if not picks:
        raise InputError("dofs must choose at least one coordinate")
    out = []
    for p in picks:
        if isinstance(p, str) and p in names:
            out.append(names[p])
        elif isinstance(p, (int, np.integer)) and not isinstance(p, bool) and 1 <= p <= n:
            out.append(int(p) - 1)
        else:
            raise InputError(f"dofs must be coordinate names {list(names)[:8]} or numbers "
                             f"1 … {n} (1-based, as in the labels), got {p!r}")
    return out


def _si(system: Any) -> bool:
    """True when every coordinate has a kind (the builders' SI units)."""
    return all(c.kind != "generalized" for c in system.coordinates)


def _unit(text: str, unit: str) -> str:
    return f"{text} ({unit})" if unit else text


def _coordinate_axes(fig: Any, trajectory: Any, kind: str, chosen: list[int]) -> list[Any]:
    """One axes per (kind, unit) of the chosen coordinates, lines labelled by name."""
    coords = trajectory.system.coordinates
    groups: dict[tuple[str, str], list[int]] = {}
    for i in chosen:
        groups.setdefault((coords[i].kind, coords[i].unit), []).append(i)
    axes = fig.subplots(len(groups), 1, sharex=True, squeeze=False)[:, 0]
    data = trajectory.q if kind == "positions" else trajectory.v
    for ax, ((ckind, unit), columns) in zip(axes, groups.items()):
        _impact_marks(ax, trajectory)
        for i in columns:
            name = coords[i].name
            ax.plot(trajectory.t, data[:, i], lw=1.1,
                    label=name if kind == "positions" else f"d{name}/dt")
        shown = unit if kind == "positions" else coords[columns[0]].rate_unit
        ax.set_ylabel(_unit(AXIS_NAMES[kind][ckind], shown))
        ax.legend(loc="upper right", fontsize=8, ncol=2)
    return list(axes)


def _energy_axes(fig: Any, tr: Any) -> list[Any]:
    ax = fig.add_subplot()
    _impact_marks(ax, tr)
    ax.plot(tr.t, tr.kinetic_energy, lw=1.0, label="kinetic T")
    ax.plot(tr.t, tr.potential_energy, lw=1.0, label="potential V")
    ax.plot(tr.t, tr.total_energy, lw=1.6, color="black", label="total T + V")
    ax.set_ylabel(_unit("energy", "J" if _si(tr.system) else ""))
    ax.legend(loc="upper right", fontsize=8)
    return [ax]


def _impulse_axes(fig: Any, tr: Any) -> list[Any]:
    """Normal impulses on one axes, tangential ones (with friction) on another."""
    d, m = tr.system.contact_dim, tr.system.n_contacts
    if m == 0:
        raise InputError("this system has no contacts: there are no impulses to draw")
    unit = "N·s" if _si(tr.system) else ""
    parts = [("normal impulse", [(j * d, f"Λ{j + 1}") for j in range(m)])]
    if d > 1:
        names = ("t", "s")
        parts.append(("tangential impulse",
                      [(j * d + c, f"Λ{j + 1},{names[c - 1]}") for j in range(m)
                       for c in range(1, d)]))
    axes = fig.subplots(len(parts), 1, sharex=True, squeeze=False)[:, 0]
    for ax, (what, columns) in zip(axes, parts):
        _impact_marks(ax, tr)
        for col, label in columns[:MAX_LINES]:
            ax.plot(tr.t, tr.impulses[:, col], lw=1.0, label=label)
        ax.set_ylabel(_unit(what, unit))
        ax.legend(loc="upper right", fontsize=8, ncol=2)
    return list(axes)


def state_intervals(t: np.ndarray, codes: np.ndarray) -> list[tuple[int, float, float]]:
    """Runs of equal state of one contact: (code, start, width) per run; a record holds its
    state from its time to the next record's."""
    if t.size < 2:
        return [(int(codes[0]), float(t[0]), 0.0)] if t.size else []
    ends = np.append(t[1:], t[-1])
    change = np.flatnonzero(np.diff(codes)) + 1
    starts = np.concatenate([[0], change])
    stops = np.append(change, t.size) - 1
    return [(int(codes[a]), float(t[a]), float(ends[b] - t[a])) for a, b in zip(starts, stops)]


def _contact_axes(fig: Any, tr: Any) -> list[Any]:
    """Each contact a row of coloured bars, one colour per state."""
    m = tr.system.n_contacts
    if m == 0:
        raise InputError("this system has no contacts: there are no contact states to draw")
    codes, names = contact_states(tr)
    ax = fig.add_subplot()
    shown = min(m, MAX_LINES * 2)
    for code, name in enumerate(names):
        bars = {j: [(a, w) for c, a, w in state_intervals(tr.t, codes[:, j]) if c == code]
                for j in range(shown)}
        for j, spans in bars.items():
            ax.broken_barh(spans, (j - 0.4, 0.8), facecolors=STATE_COLORS[name],
                           label=name if j == 0 else None)
    ax.set_yticks(range(shown), [f"contact {j + 1}" for j in range(shown)])
    ax.set_ylim(-0.6, shown - 0.4)
    ax.invert_yaxis()
    ax.legend(loc="upper right", fontsize=8, ncol=len(names))
    return [ax]


def plot(trajectory: Any, kind: str = "positions", path: str | Path | None = None, *,
         title: str = "", dofs: Any = None) -> Any:
    """A quantity of a run over time; impacts of an event-driven run are marked by thin
    vertical lines.

    Parameters
    ----------
    trajectory : Trajectory
    kind : {"positions", "velocities", "energy", "impulses", "contacts"}
        ``"positions"`` and ``"velocities"``: the coordinates chosen by ``dofs``, one axes
        per kind of coordinate (translations, rotations, coordinates of unknown kind), each
        labelled with its unit; ``"energy"``: T, V and T + V; ``"impulses"``: the contact
        impulses Λ, normal and (with friction) tangential on axes of their own;
        ``"contacts"``: each contact's state over time, open or closed, and with friction
        open, stick or slide (:func:`~impactqp.simulation.contact_states.contact_states`).
    path : str or Path, optional
        Where to write the figure (``.png``, ``.svg`` or ``.pdf``).
    title : str
        Title of the top axes (default: scheme, law and kind).
    dofs : int, str or sequence of them, optional
        The coordinates drawn (``"positions"``, ``"velocities"``): names as the system gives
        them (``"x"``, ``"φ"``, ``"q2"``) or 1-based numbers, as in the labels; default the
        first 12.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InputError
        Unknown ``kind``, bad ``dofs``, no contacts to draw, or an unknown file suffix.
    OptionalDependencyError
        matplotlib is missing.
    """
    if kind not in KINDS:
        raise InputError(f"kind must be one of {KINDS}, got {kind!r}")
    if path is not None:
        figure_format(path)
    tr = trajectory
    chosen = chosen_dofs(tr.system.coordinates, dofs) if kind in AXIS_NAMES else None
    if dofs is not None and chosen is None:
        raise InputError(f"dofs chooses coordinates of 'positions' or 'velocities', not of "
                         f"{kind!r}")
    groups = len({(tr.system.coordinates[i].kind, tr.system.coordinates[i].unit)
                  for i in chosen}) if chosen else 1
    groups = 2 if kind == "impulses" and tr.system.contact_dim > 1 else groups
    fig = new_figure(6.4, 1.2 + 2.4 * groups)
    if kind in AXIS_NAMES:
        axes = _coordinate_axes(fig, tr, kind, chosen)
    elif kind == "energy":
        axes = _energy_axes(fig, tr)
    elif kind == "impulses":
        axes = _impulse_axes(fig, tr)
    else:
        axes = _contact_axes(fig, tr)
    axes[-1].set_xlabel(_unit("t", "s" if _si(tr.system) else ""))
    axes[0].set_title(title or f"{tr.scheme}, {tr.law!r}: {kind}", fontsize=10)
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


def animate(trajectory: Any, path: str | Path | None = None, *, length: float | None = None,
            radius: float | None = None, frames: int = 120, fps: int = 24,
            size: float = 3.2) -> Any:
    """An animation of the bodies of a builder's system
    (:func:`~impactqp.simulation.scenes.draw_scene`), written when given a path.

    Parameters
    ----------
    trajectory : Trajectory
    path : str or Path, optional
        ``.gif`` (Pillow) or ``.mp4`` (ffmpeg). Without one, keep the returned animation and
        save or display it: matplotlib warns when an animation is discarded unshown.
    length, radius : float, optional
        Pendulum length and ball radius of the drawing (default: the builder's; pivots one
        diameter apart).
    frames, fps : int
        Number of frames (equally spaced in time) and frames per second.
    size : float
        Width of the picture in inches.

    Returns
    -------
    matplotlib.animation.FuncAnimation

    Raises
    ------
    UndrawableSystemError
        A system whose bodies are unknown (built from matrices), saying what can be drawn.
    InputError
        Another suffix, or bad numbers.
    OptionalDependencyError
        matplotlib is missing.
    """
    suffix = None if path is None else Path(path).suffix.lower()
    if suffix is not None and suffix not in MOVIE_FORMATS:
        raise InputError(f"animation file must end in one of {MOVIE_FORMATS}, got "
                         f"{Path(path).name!r}")
    length = None if length is None else as_real("length", length, positive=True)
    radius = None if radius is None else as_real("radius", radius, positive=True)
    size = as_real("size", size, positive=True)
    frames, fps = as_count("frames", frames, minimum=2), as_count("fps", fps, minimum=1)
    if getattr(trajectory.system, "scene", None) is None:
        draw_scene(trajectory, None, trajectory.q)  # refuses by name, before any figure
    fig = new_figure(size, 0.75 * size)
    try:
        from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter
    except ImportError:
        raise OptionalDependencyError("animations need matplotlib: pip install "
                                      "'impactqp[plot]'") from None
    times, Q = frames_of(trajectory, frames)
    ax = fig.add_subplot()
    update = draw_scene(trajectory, ax, Q, length=length, radius=radius)
    # the clock sits in the top corner, where no body is drawn
    clock = ax.text(0.02, 0.98, "", transform=ax.transAxes, fontsize=8, va="top")

    def draw(k: int) -> list:
        clock.set_text(f"t = {times[k]:.2f}")
        return update(Q[k]) + [clock]

    movie = FuncAnimation(fig, draw, frames=frames, interval=1000.0 / fps, blit=False)
    if path is not None:
        writer = PillowWriter(fps=fps) if suffix == ".gif" else FFMpegWriter(fps=fps)
        with atomic_output(path) as temp:
            movie.save(str(temp), writer=writer, dpi=DPI)
    return movie
