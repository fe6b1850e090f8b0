"""Figures of S (docs/theory.md §2–§5) and of the sector law (docs/theory.md §6), drawn from
:mod:`impactqp.figures.geometry2d`.

matplotlib is an optional extra (``pip install 'impactqp[plot]'``), imported only here and
only when a figure is drawn. Figures are built on a bare :class:`matplotlib.figure.Figure`
(no pyplot, no global state), so they render headless; the format follows the suffix of the
output file (``.png``, ``.svg`` or ``.pdf``).

Regions are drawn so that what the legend shows is what the picture shows: opaque fills
(u⁻ + N light blue, S green) and a hatch for T_C, with no transparency that would mix
colours where regions overlap; the edge of T_C is drawn wide under the thinner lines that
share it (Moreau's half-line), so that neither hides the other.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..base.figure import figure_format, new_figure, save_figure
from ..model.builders import newtons_cradle
from ..model.problem import ImpactProblem
from ..tables.sector_table import sector_velocity_map
from .geometry2d import PlanePicture, Wedge, plane_picture, sector_picture

COLORS = {"reaction": ("#d6e6f4", "tab:blue"), "tangent": "tab:orange", "S": "#74c476"}
"""Fill and edge colours of the regions of :func:`draw_plane`."""

CANDIDATE_MARKERS = ("*", "D", "P", "X", "^", "v", "p")
CANDIDATE_COLORS = ("crimson", "#6a3d9a", "#e7298a", "#8c510a", "#01665e", "#525252")
"""Markers and colours of the candidates of :func:`draw_plane`: the k-th candidate takes
marker k mod 7 and colour k mod 6, so no two of the first 42 candidates look alike, and none
takes the colours of the regions or of Moreau's half-line."""


def candidate_style(k: int) -> dict[str, Any]:
    """The matplotlib line style of the k-th candidate of :func:`draw_plane`.

    The first is a large filled star; the others are hollow and smaller, so a candidate
    drawn on top of another (two laws giving the same u⁺) leaves the one below visible.
    """
    color = CANDIDATE_COLORS[k % len(CANDIDATE_COLORS)]
    if k == 0:
        return {"marker": CANDIDATE_MARKERS[0], "color": color, "ms": 15, "ls": "none"}
    return {"marker": CANDIDATE_MARKERS[k % len(CANDIDATE_MARKERS)], "color": color,
            "mfc": "none", "mew": 2.0, "ms": 9, "ls": "none"}


def _edges(polygon: np.ndarray, half_width: float) -> np.ndarray:
    """The edges of a polygon clipped to the view square, without those that lie on the
    square's border (they are not edges of the region): one (k, 2) path, NaN between
    pieces."""
    on = np.isclose(np.abs(polygon), half_width, rtol=0, atol=1e-9 * half_width)
    pieces = []
    for i in range(len(polygon)):
        j = (i + 1) % len(polygon)
        a, b = polygon[i], polygon[j]
        border = any(on[i, k] and on[j, k] and np.sign(a[k]) == np.sign(b[k]) for k in (0, 1))
        if not border:
            pieces += [a, b, [np.nan, np.nan]]
    return np.array(pieces, dtype=float).reshape(-1, 2)


def draw_plane(picture: PlanePicture, ax: Any, title: str = "",
               plane: str = "the plane u⁻ + range(M⁻¹W)") -> None:
    """Draw S, u⁻ + N, T_C, the energy circle, Moreau's half-line and the candidates
    (docs/theory.md §5).

    Each candidate has a marker and a colour of its own (:func:`candidate_style`), its arc
    from Moreau's half-line on a radius of its own, and its legend entry names it with its
    angle α; the legend lies below the axes, so no text is written over the picture.

    Parameters
    ----------
    picture : PlanePicture
        From :func:`~impactqp.figures.geometry2d.plane_picture`.
    ax : matplotlib.axes.Axes
        Where to draw.
    title : str
        Axes title.
    plane : str
        How the axis labels name the plane (its coordinates are M-orthonormal).
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    h = picture.half_width
    fill, edge = COLORS["reaction"]
    ax.fill(*picture.reaction_cone.T, fc=fill, lw=0, zorder=1)
    ax.plot(*_edges(picture.reaction_cone, h).T, color=edge, lw=1.3, zorder=2)
    ax.fill(*picture.tangent_cone.T, fc="none", ec=COLORS["tangent"], hatch="///", lw=0,
            zorder=1.5)
    ax.plot(*_edges(picture.tangent_cone, h).T, color=COLORS["tangent"], lw=4.0,
            solid_capstyle="butt", zorder=2.5)
    ax.fill(*picture.admissible.T, fc=COLORS["S"], lw=0, zorder=2)
    circle = np.vstack([picture.circle, picture.circle[:1]])
    ax.plot(*circle.T, ls="--", color="0.3", lw=1.0, zorder=3)
    ax.plot(*picture.moreau_line.T, color="black", lw=1.4, zorder=3)
    for eps, x in picture.moreau_marks.items():
        ax.plot(*x, "o", color="black", ms=5, zorder=4)
        ax.annotate(f"ε = {eps:g}" + (" (z)" if eps == 0 else ""), x, xytext=(-12, 0),
                    textcoords="offset points", ha="right", va="center", fontsize=9,
                    zorder=6, bbox={"fc": "white", "ec": "none", "pad": 0.5})
    ax.plot(*picture.u_minus, "s", color="black", ms=6, zorder=4)
    ax.annotate("u⁻", picture.u_minus, xytext=(6, 4), textcoords="offset points", fontsize=11)
    handles = [
        Patch(fc=fill, ec=edge, lw=1.3, label="u⁻ + N"),
        Patch(fc="none", ec=COLORS["tangent"], hatch="///", lw=2.5,
              label="T_C (its trace in the plane)"),
        Patch(fc=COLORS["S"], label="S"),
        Line2D([], [], ls="--", color="0.3", lw=1.0, label="energy circle ‖u‖ = ‖u⁻‖"),
        Line2D([], [], color="black", lw=1.4, marker="o", ms=4,
               label="Moreau's half-line (ε marked)"),
    ]
    for k, cand in enumerate(picture.candidates):
        style = candidate_style(k)
        alpha = ("α undefined: u⁺ = u⁻" if np.isnan(cand.alpha_deg)
                 else f"α = {cand.alpha_deg:.1f}°")
        (mark,) = ax.plot(*cand.point, zorder=5 + 0.01 * k, label=f"{cand.label} ({alpha})",
                          **style)
        handles.append(mark)
        if len(cand.arc):
            ax.plot(*cand.arc.T, color=style["color"], lw=1.2, zorder=4)
            ax.plot(*np.array([picture.u_minus, cand.point]).T, color=style["color"], lw=0.9,
                    ls=":", zorder=4)
    ax.set_xlim(-h, h)
    ax.set_ylim(-h, h)
    ax.set_aspect("equal")
    ax.set_xlabel(f"x₁: M-orthonormal coordinate in {plane}, ⊥ Moreau's half-line",
                  fontsize=9)
    ax.set_ylabel(f"x₂: M-orthonormal coordinate in {plane}, along u⁻ − z", fontsize=9)
    # below the axes: the α of each candidate is read there, never written over the picture
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.09), ncol=2,
              fontsize=8, frameon=False)
    ax.set_title(title, fontsize=10)


def draw_sectors(wedges: list[Wedge], ax: Any, radius: float = 1.0) -> None:
    """Draw the six cones of the γ⁻ plane with their Q and sample points γ⁻ ↦ γ⁺
    (docs/theory.md §6), in the G⁻¹-orthonormal coordinates of the wedges.

    Parameters
    ----------
    wedges : list of Wedge
        From :func:`~impactqp.figures.geometry2d.sector_picture`.
    ax : matplotlib.axes.Axes
        Where to draw.
    radius : float
        Radius of the wedges.
    """
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]
    for wedge, color in zip(wedges, colors):
        ax.fill(*wedge.polygon.T, color=color, alpha=0.18, lw=0)
        ax.text(*wedge.anchor, wedge.text, ha="center", va="center", fontsize=8)
        ax.plot(*wedge.sample, "o", color=color, ms=5)
        ax.annotate("", wedge.image, xytext=wedge.sample,
                    arrowprops={"arrowstyle": "->", "color": color, "lw": 1.2})
        ax.plot(*wedge.image, "x", color=color, ms=7, mew=1.5)
    to_y = np.linalg.inv(wedges[0].frame)
    for gamma, name in (([1, 0], "γ₂ = 0"), ([0, 1], "γ₁ = 0"), ([1, -1], "γ₁ + γ₂ = 0")):
        d = to_y @ np.array(gamma, dtype=float)
        d *= radius / np.linalg.norm(d)
        ax.plot([-d[0], d[0]], [-d[1], d[1]], color="0.3", lw=0.8)
        ax.annotate(name, d, xytext=6 * d / radius, textcoords="offset points", fontsize=8,
                    color="0.3", ha="left" if d[0] > 0.01 else "center",
                    va="bottom" if d[1] >= 0 else "top")
    lim = 1.15 * radius
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("y₁: G⁻¹-orthonormal coordinate of the γ⁻ plane (γ = L y, G = WᵀM⁻¹W = LLᵀ)",
                  fontsize=9)
    ax.set_ylabel("y₂: G⁻¹-orthonormal coordinate (γᵀG⁻¹γ = y₁² + y₂²)", fontsize=9)
    ax.set_title("Sector law, 3 equal balls: γ⁺ = Q γ⁻ on each cone (u⁺ = sort(u⁻));\n"
                 "in the kinetic metric G⁻¹ every cone is 60° and every Q an isometry.\n"
                 "dots: sample γ⁻, crosses: their images γ⁺ (all in γ ≥ 0)", fontsize=10)


def plot_S(problem: ImpactProblem, path: str | Path,
           candidates: Mapping[str, ArrayLike] | None = None, title: str = "",
           plane: str = "the plane u⁻ + range(M⁻¹W)") -> Path:
    """Write the picture of S for a problem with two independent contacts.

    Parameters
    ----------
    problem : ImpactProblem
        Two contacts with independent directions, at least one approaching.
    path : str or Path
        Output file; the format follows the suffix (``.png``, ``.svg`` or ``.pdf``).
    candidates : mapping of label → (n,) array_like, optional
        Post-impact velocities to mark, each with a marker of its own; the legend names
        each with its angle α to Moreau's half-line.
    title : str
        Figure title (default: what S is).
    plane : str
        How the axis labels name the plane of the picture.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    InputError
        For an unknown suffix, or a problem or candidate that cannot be drawn in the plane.
    OptionalDependencyError
        When matplotlib is not installed.
    """
    figure_format(path)
    picture = plane_picture(problem, candidates)
    fig = new_figure(6.4, 7.4)
    draw_plane(picture, fig.add_subplot(), title or "S = (u⁻ + N) ∩ T_C ∩ B(0, ‖u⁻‖) in the "
               "plane u⁻ + range(M⁻¹W)", plane=plane)
    return save_figure(fig, path)


def plot_cradle(path: str | Path, v: float = 1.0) -> Path:
    """Write the picture of docs/theory.md §5: the 3-ball cradle's S, Moreau's half-line and
    the sector-law point (0, 0, v) at α = 30°, in the plane u₁ + u₂ + u₃ = v.

    Parameters
    ----------
    path : str or Path
        Output file; the format follows the suffix (``.png``, ``.svg`` or ``.pdf``).
    v : float
        Speed of the released ball (positive).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    InputError
        For an unknown suffix or v ≤ 0 (nothing to draw).
    OptionalDependencyError
        When matplotlib is not installed.
    """
    p = newtons_cradle(3, v=v)
    return plot_S(p, path, {"sector law u⁺ = (0, 0, v)": sector_velocity_map(p.u_minus)},
                  title=f"3-ball Newton's cradle, u⁻ = (v, 0, 0), v = {v:g}: the plane "
                        "u₁ + u₂ + u₃ = v", plane="the plane u₁+u₂+u₃ = v")


def plot_sectors(path: str | Path) -> Path:
    """Write the figure of the six cones of the 3-ball sector law (docs/theory.md §6).

    Parameters
    ----------
    path : str or Path
        Output file; the format follows the suffix (``.png``, ``.svg`` or ``.pdf``).

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    InputError
        For an unknown suffix.
    OptionalDependencyError
        When matplotlib is not installed.
    """
    figure_format(path)
    fig = new_figure()
    draw_sectors(sector_picture(), fig.add_subplot())
    return save_figure(fig, path)
