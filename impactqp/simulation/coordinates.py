"""What the generalized coordinates of a system are (docs/theory.md §14): a name, a kind
(translation, rotation or a coordinate of unknown kind) and a unit, for the figures of a
motion; and what bodies a builder's system holds, for its animation.

The builders of :mod:`impactqp.simulation.builders` name their coordinates (``x``, ``y``,
``φ``, ``q1`` …) and describe their bodies (:class:`Scene`); a system built from matrices
has the coordinates ``q1 … qn`` of unknown kind and no scene unless it is given one.
Coordinates are numbered from 1 in every label, and a figure's ``dofs=`` takes these names
or the same 1-based numbers.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from ..errors import InputError, ShapeError

KINDS = {"translation": "m", "rotation": "rad", "generalized": ""}
"""Kinds of coordinate and the unit each has by default (SI, as the builders)."""

RATES = {"m": "m/s", "rad": "rad/s", "": ""}
"""Unit of the velocity of a coordinate, by the coordinate's unit."""


@dataclass(frozen=True)
class Coordinate:
    """One generalized coordinate qᵢ of a system.

    Attributes
    ----------
    name : str
        What figures call it (``"x"``, ``"φ"``, ``"q3"``); unique within a system.
    kind : str
        ``"translation"``, ``"rotation"`` or ``"generalized"`` (of unknown kind): figures
        draw each kind on axes of its own.
    unit : str
        The unit of qᵢ (``"m"``, ``"rad"``; empty when unknown); by default the kind's.
    """

    name: str
    kind: str = "generalized"
    unit: str | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise InputError(f"a coordinate's name must be a non-empty string, got "
                             f"{self.name!r}")
        if self.kind not in KINDS:
            raise InputError(f"coordinate {self.name!r}: kind must be one of {list(KINDS)}, "
                             f"got {self.kind!r}")
        if self.unit is None:
            object.__setattr__(self, "unit", KINDS[self.kind])
        elif not isinstance(self.unit, str):
            raise InputError(f"coordinate {self.name!r}: unit must be a string, got "
                             f"{self.unit!r}")

    @property
    def rate_unit(self) -> str:
        """The unit of the coordinate's velocity (``"m/s"``, ``"rad/s"``, or ``unit/s``)."""
        unit = self.unit or ""
        return RATES.get(unit, f"{unit}/s")


def default_coordinates(n: int) -> tuple[Coordinate, ...]:
    """``q1 … qn``, of unknown kind and unit (a system built from matrices)."""
    return tuple(Coordinate(f"q{i + 1}") for i in range(n))


def as_coordinates(value: Any, n: int) -> tuple[Coordinate, ...]:
    """The coordinates of a system of n degrees of freedom from what a caller gives.

    Parameters
    ----------
    value : None or sequence
        None (``q1 … qn``), or n entries, each a :class:`Coordinate`, a name (a coordinate
        of unknown kind) or a pair (name, kind).
    n : int
        Number of degrees of freedom.

    Returns
    -------
    tuple of Coordinate

    Raises
    ------
    ShapeError
        Not n entries.
    InputError
        An entry of another type, an unknown kind, a repeated name.
    """
    if value is None:
        return default_coordinates(n)
    if isinstance(value, (str, bytes)) or not isinstance(value, Sequence):
        raise InputError(f"coordinates must be a sequence of n = {n} names or Coordinates, "
                         f"got {type(value).__name__}")
    if len(value) != n:
        raise ShapeError(f"coordinates must name all n = {n} degrees of freedom, got "
                         f"{len(value)}")
    out = []
    for entry in value:
        if isinstance(entry, Coordinate):
            out.append(entry)
        elif isinstance(entry, str):
            out.append(Coordinate(entry))
        elif isinstance(entry, tuple) and len(entry) == 2:
            out.append(Coordinate(*entry))
        else:
            raise InputError(f"a coordinate is a Coordinate, a name or a pair (name, kind), "
                             f"got {entry!r}")
    names = [c.name for c in out]
    if len(set(names)) != n:
        raise InputError(f"coordinate names must be distinct, got {names}")
    return tuple(out)


SCENES = ("pendulums", "vertical balls", "sphere", "block on incline", "box")
"""The bodies :meth:`Trajectory.animate <impactqp.Trajectory.animate>` can draw, by the
builders that make them: balls on pendulums (``cradle_system``), balls on a vertical line
(``bouncing_ball``, ``bead_chain``), a rolling sphere (``rolling_sphere``), a block on an
incline (``block_on_incline``) and a box on a floor (``box_on_floor``)."""


@dataclass(frozen=True)
class Scene:
    """The bodies of a builder's system, as its animation draws them.

    Attributes
    ----------
    kind : str
        One of ``SCENES``.
    sizes : mapping of str to float or tuple
        The builder's lengths the drawing needs (``radius``, ``length``, ``angle``,
        ``half_sizes``, ``dim`` …).
    """

    kind: str
    sizes: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.kind not in SCENES:
            raise InputError(f"scene kind must be one of {list(SCENES)}, got {self.kind!r}")
