"""Pictures of a simulated motion written to files (docs/theory.md §14): the file-writing
forms of :meth:`Trajectory.plot <impactqp.Trajectory.plot>` and
:meth:`Trajectory.animate <impactqp.Trajectory.animate>`, which draw them
(:mod:`impactqp.simulation.pictures`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from ..simulation import pictures
from ..simulation.trajectory import Trajectory


def _check(trajectory: Any) -> Trajectory:
    if not isinstance(trajectory, Trajectory):
        raise InputError(f"trajectory must be an impactqp Trajectory (from iq.simulate), got "
                         f"{type(trajectory).__name__}")
    return trajectory


def plot_energy(trajectory: Trajectory, path: str | Path, title: str = "") -> Path:
    """Write kinetic, potential and total energy over time (``trajectory.plot("energy")``)."""
    pictures.plot(_check(trajectory), "energy", path, title=title)
    return Path(path)


def plot_positions(trajectory: Trajectory, path: str | Path, title: str = "",
                   dofs: Any = None) -> Path:
    """Write the coordinates over time, one axes per kind (``trajectory.plot("positions")``);
    ``dofs`` chooses them by name or by 1-based number, as the labels show."""
    pictures.plot(_check(trajectory), "positions", path, title=title, dofs=dofs)
    return Path(path)


def cradle_frames(trajectory: Trajectory, frames: int) -> tuple[np.ndarray, np.ndarray]:
    """(times, positions) at ``frames`` equally spaced times (what an animation shows)."""
    return pictures.frames_of(_check(trajectory), frames)


def animate_cradle(trajectory: Trajectory, path: str | Path, **options: Any) -> Path:
    """Write an animation of a run (``trajectory.animate(path, **options)``): a cradle's
    balls on their pendulums, or the bodies of any other builder's system."""
    pictures.animate(_check(trajectory), path, **options)
    return Path(path)
