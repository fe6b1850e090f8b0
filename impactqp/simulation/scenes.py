"""The bodies of a builder's system drawn on matplotlib axes (docs/theory.md §14), for the
animations of :func:`impactqp.simulation.pictures.animate`: balls on pendulums, balls on a
vertical line, a rolling sphere with a radius that turns with it, a block on an incline and
a box on a floor. A system built from matrices has no bodies and is refused by name.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..errors import UndrawableSystemError
from .coordinates import SCENES

CAN_DRAW = ("balls on pendulums (cradle_system), balls on a vertical line (bouncing_ball, "
            "bead_chain), a sphere rolling in the plane (rolling_sphere), a block on an "
            "incline (block_on_incline) and a box on a floor (box_on_floor)")
"""What :func:`~impactqp.simulation.pictures.animate` draws, as its refusal says."""

Update = Callable[[np.ndarray], list]


def _rectangle(center: np.ndarray, half: tuple[float, float], angle: float) -> np.ndarray:
    """Corners of a rectangle of half sides ``half`` turned by ``angle`` about its centre."""
    c, s = np.cos(angle), np.sin(angle)
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * np.asarray(half)
    return center + corners @ np.array([[c, s], [-s, c]])


def _view(ax: Any, x: tuple[float, float], y: tuple[float, float]) -> None:
    ax.set_xlim(*x)
    ax.set_ylim(*y)
    ax.set_aspect("equal")
    ax.axis("off")


def _pendulums(ax: Any, Q: np.ndarray, sizes: dict, length: float | None,
               radius: float | None) -> Update:
    from matplotlib.patches import Circle

    length = sizes["length"] if length is None else length
    radius = 0.05 * length if radius is None else radius
    n = Q.shape[1]
    pivots = 2.0 * radius * (np.arange(n) - (n - 1) / 2.0)
    reach = max(np.abs(Q).max(), radius) + pivots[-1] + 2 * radius
    _view(ax, (-reach, reach), (-length - 2 * radius, 0.1 * length))
    ax.plot([pivots[0] - radius, pivots[-1] + radius], [0, 0], color="0.3", lw=2)
    strings = [ax.plot([], [], color="0.4", lw=0.8)[0] for _ in range(n)]
    balls = [ax.add_patch(Circle((0, 0), radius, fc="tab:blue", ec="black", lw=0.6))
             for _ in range(n)]

    def update(q: np.ndarray) -> list:
        x = pivots + q
        y = -np.sqrt(np.maximum(length**2 - q**2, 0.0))
        for i in range(n):
            strings[i].set_data([pivots[i], x[i]], [0.0, y[i]])
            balls[i].center = (x[i], y[i])
        return strings + balls

    return update


def _vertical_balls(ax: Any, Q: np.ndarray, sizes: dict, radius: float | None) -> Update:
    """Balls on a vertical line above the ground; q is a centre's height, or the lowest
    point's for balls of radius 0 (as the builders measure it), drawn with a small radius."""
    from matplotlib.patches import Circle

    top = float(Q.max())
    r = sizes["radius"] if radius is None else radius
    r = r if r > 0 else 0.05 * max(top, 1e-3)
    lift = r if sizes["radius"] == 0 else 0.0
    n = Q.shape[1]
    _view(ax, (-4 * r, 4 * r), (-0.5 * r, top + lift + 1.5 * r))
    ax.plot([-4 * r, 4 * r], [0, 0], color="0.3", lw=2)
    balls = [ax.add_patch(Circle((0, 0), r, fc="tab:blue", ec="black", lw=0.6))
             for _ in range(n)]

    def update(q: np.ndarray) -> list:
        for i in range(n):
            balls[i].center = (0.0, q[i] + lift)
        return balls

    return update


def _sphere(ax: Any, Q: np.ndarray, sizes: dict) -> Update:
    """A sphere seen from the side with a radius drawn on it that turns with φ."""
    from matplotlib.patches import Circle

    R = sizes["radius"]
    x0, x1 = float(Q[:, 0].min()) - 2 * R, float(Q[:, 0].max()) + 2 * R
    _view(ax, (x0, x1), (-0.5 * R, float(Q[:, 1].max()) + 1.5 * R))
    ax.plot([x0, x1], [0, 0], color="0.3", lw=2)
    ball = ax.add_patch(Circle((0, 0), R, fc="tab:blue", ec="black", lw=0.6))
    (mark,) = ax.plot([], [], color="white", lw=2.0)

    def update(q: np.ndarray) -> list:
        x, y, phi = q[0], q[1], q[2]
        ball.center = (x, y)
        mark.set_data([x, x - R * np.sin(phi)], [y, y + R * np.cos(phi)])
        return [ball, mark]

    return update


def _block_on_incline(ax: Any, Q: np.ndarray, sizes: dict) -> Update:
    """The incline through the origin and the block on it, seen from the side (x, up)."""
    from matplotlib.patches import Polygon

    alpha = sizes["angle"]
    P = Q[:, [0, -1]]  # the plane (x, y), or the side view (x, z) of space
    along = P @ np.array([np.cos(alpha), np.sin(alpha)])
    span = max(float(np.ptp(along)), 0.2)
    half = 0.06 * span
    lo, hi = float(along.min()) - 4 * half, float(along.max()) + 4 * half
    slope = np.array([[np.cos(alpha), np.sin(alpha)]]) * np.array([[lo], [hi]])
    normal = np.array([-np.sin(alpha), np.cos(alpha)])
    ax.plot(*slope.T, color="0.3", lw=2)
    pad = 3 * half
    _view(ax, (slope[:, 0].min() - pad, slope[:, 0].max() + pad),
          (min(slope[:, 1].min(), float(P[:, 1].min())) - pad,
           max(slope[:, 1].max(), float(P[:, 1].max())) + pad))
    block = ax.add_patch(Polygon(np.zeros((4, 2)), closed=True, fc="tab:orange", ec="black",
                                 lw=0.6))

    def update(q: np.ndarray) -> list:
        block.set_xy(_rectangle(q[[0, -1]] + half * normal, (half, half), alpha))
        return [block]

    return update


def _box(ax: Any, Q: np.ndarray, sizes: dict) -> Update:
    """The box seen from the side: (x, y, φ) in the plane, (x, z) turned by −ρy in space."""
    from matplotlib.patches import Polygon

    half = sizes["half_sizes"]
    X, Y = (Q[:, 0], Q[:, 1]) if sizes["dim"] == 2 else (Q[:, 0], Q[:, 2])
    hx, hy = half[0], half[-1]
    reach = np.hypot(hx, hy)
    x0, x1 = float(X.min()) - 2 * reach, float(X.max()) + 2 * reach
    _view(ax, (x0, x1), (-0.5 * hy, float(Y.max()) + 1.5 * reach))
    ax.plot([x0, x1], [0, 0], color="0.3", lw=2)
    box = ax.add_patch(Polygon(np.zeros((4, 2)), closed=True, fc="tab:orange", ec="black",
                               lw=0.6))
    columns = [0, 1, 2] if sizes["dim"] == 2 else [0, 2, 4]
    sign = 1.0 if sizes["dim"] == 2 else -1.0

    def update(q: np.ndarray) -> list:
        x, y, a = q[columns]
        box.set_xy(_rectangle(np.array([x, y]), (hx, hy), sign * a))
        return [box]

    return update


def draw_scene(trajectory: Any, ax: Any, Q: np.ndarray, *, length: float | None = None,
               radius: float | None = None) -> Update:
    """Draw the bodies of a builder's system on ``ax`` and return the function that moves
    them to a position q (what each frame of :func:`~impactqp.simulation.pictures.animate` calls).

    Parameters
    ----------
    trajectory : Trajectory
        Its system's ``scene`` names the bodies (:data:`~impactqp.simulation.coordinates.SCENES`).
    ax : matplotlib.axes.Axes
    Q : (k, n) ndarray
        The positions to be shown (they set the view).
    length, radius : float, optional
        Pendulum length and ball radius of the drawing, instead of the builder's.

    Returns
    -------
    callable
        ``update(q)`` → the artists it moved.

    Raises
    ------
    UndrawableSystemError
        A system without a scene (built from matrices), saying what can be drawn.
    """
    scene = getattr(trajectory.system, "scene", None)
    if scene is None or scene.kind not in SCENES:
        raise UndrawableSystemError(
            f"cannot animate {trajectory.system!r}: it has no bodies to draw (a system built "
            f"from matrices). animate draws {CAN_DRAW}; plot its coordinates with "
            "trajectory.plot('positions')")
    sizes = dict(scene.sizes)
    if scene.kind == "pendulums":
        return _pendulums(ax, Q, sizes, length, radius)
    if scene.kind == "vertical balls":
        return _vertical_balls(ax, Q, sizes, radius)
    if scene.kind == "sphere":
        return _sphere(ax, Q, sizes)
    if scene.kind == "block on incline":
        return _block_on_incline(ax, Q, sizes)
    return _box(ax, Q, sizes)
