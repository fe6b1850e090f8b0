"""Drawing S (docs/theory.md §2–§5) and the cones of the sector law (docs/theory.md §6) on
matplotlib axes, from the data of :mod:`impactqp.figures.geometry2d`; the figures that use
them are in :mod:`impactqp.figures.sections`.

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

from typing import Any

import numpy as np

from .cone_section import Wedge
from .geometry2d import PlanePicture

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
               plane: str = "the plane u⁻ + range(M⁻¹W)", notes: list[str] | None = None,
               ) -> None:
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
    notes : list of str, optional
        Lines added to the legend (laws that are not defined for the problem, say).
    """
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    h = picture.half_width
    fill, edge = COLORS["reaction"]
    if len(picture.reaction_cone) > 2:
        ax.fill(*picture.reaction_cone.T, fc=fill, lw=0, zorder=1)
        ax.plot(*_edges(picture.reaction_cone, h).T, color=edge, lw=1.3, zorder=2)
    else:  # the trace of u⁻ + N is a ray (or u⁻ alone)
        ax.plot(*picture.reaction_cone.T, color=edge, lw=1.3, zorder=2)
    ax.fill(*picture.tangent_cone.T, fc="none", ec=COLORS["tangent"], hatch="///", lw=0,
            zorder=1.5)
    ax.plot(*_edges(picture.tangent_cone, h).T, color=COLORS["tangent"], lw=4.0,
            solid_capstyle="butt", zorder=2.5)
    if len(picture.admissible) > 2:
        ax.fill(*picture.admissible.T, fc=COLORS["S"], lw=0, zorder=2)
    else:  # a section that is a segment
        ax.plot(*picture.admissible.T, color=COLORS["S"], lw=6, solid_capstyle="butt",
                zorder=2)
    circle = np.vstack([picture.circle, picture.circle[:1]])
    ax.plot(*circle.T, ls="--", color="0.3", lw=1.0, zorder=3)
    if len(picture.moreau_line):
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
    ]
    if len(picture.moreau_line):
        handles.append(Line2D([], [], color="black", lw=1.4, marker="o", ms=4,
                              label="Moreau's half-line (ε marked)"))
    for k, cand in enumerate(picture.candidates):
        style = candidate_style(k)
        alpha = ("α undefined: u⁺ = u⁻" if np.isnan(cand.alpha_deg)
                 else f"α = {cand.alpha_deg:.1f}°")
        if cand.off_plane > 1e-9:
            alpha += f"; off the plane by {cand.off_plane:.2g}‖u⁻‖, projected"
        (mark,) = ax.plot(*cand.point, zorder=5 + 0.01 * k, label=f"{cand.label} ({alpha})",
                          **style)
        handles.append(mark)
        if len(cand.arc):
            ax.plot(*cand.arc.T, color=style["color"], lw=1.2, zorder=4)
            ax.plot(*np.array([picture.u_minus, cand.point]).T, color=style["color"], lw=0.9,
                    ls=":", zorder=4)
    handles += [Line2D([], [], ls="none", label=note) for note in notes or []]
    ax.set_xlim(-h, h)
    ax.set_ylim(-h, h)
    ax.set_aspect("equal")
    moreau = len(picture.moreau_line) > 0
    ax.set_xlabel(f"x₁: M-orthonormal coordinate in {plane}"
                  + (", ⊥ Moreau's half-line" if moreau else ""), fontsize=9)
    ax.set_ylabel(f"x₂: M-orthonormal coordinate in {plane}"
                  + (", along u⁻ − z" if moreau else ""), fontsize=9)
    # below the axes: the α of each candidate is read there, never written over the picture
    wide = any(len(line) > 48 for h in handles for line in h.get_label().split("\n"))
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.09),
              ncol=1 if wide else 2, fontsize=8, frameon=False)
    ax.set_title(title, fontsize=10)


def draw_sectors(wedges: list[Wedge], ax: Any, radius: float = 1.0, title: str | None = None,
                 gamma: tuple[np.ndarray, np.ndarray] | None = None) -> None:
    """Draw the cones of a piecewise-linear law cut by a plane of γ⁻ with their labels and
    sample points γ⁻ ↦ γ⁺ (docs/theory.md §6, §10), in the G⁻¹-orthonormal coordinates of
    the wedges.

    Parameters
    ----------
    wedges : list of Wedge
        From :func:`~impactqp.figures.cone_section.cone_section`.
    ax : matplotlib.axes.Axes
        Where to draw.
    radius : float
        Radius of the wedges.
    title : str, optional
        Axes title (default: that of the 3-ball sector law).
    gamma : pair of (2,) arrays, optional
        A γ⁻ and its γ⁺ in the plane's coordinates, drawn as a black arrow (a problem's).

    Notes
    -----
    The image of a sample that leaves the plane (γ-space of more than two contacts) is not
    drawn: its arrow would point at a projection.
    """
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown",
              "tab:pink", "tab:olive", "tab:cyan", "tab:gray"]
    full = wedges[0].frame.shape[1] == wedges[0].frame.shape[0]  # γ-space is the plane
    for k, wedge in enumerate(wedges):
        color = colors[k % len(colors)]
        ax.fill(*wedge.polygon.T, color=color, alpha=0.18, lw=0)
        ax.text(*wedge.anchor, wedge.text, ha="center", va="center",
                fontsize=8 if full and len(wedges) <= 6 else 6)
        if wedge.off_plane <= 1e-9:
            ax.plot(*wedge.sample, "o", color=color, ms=5)
            ax.annotate("", wedge.image, xytext=wedge.sample,
                        arrowprops={"arrowstyle": "->", "color": color, "lw": 1.2})
            ax.plot(*wedge.image, "x", color=color, ms=7, mew=1.5)
    for wedge in wedges:  # the boundaries of the cones
        ax.plot([0, radius * wedge.rays[0][0]], [0, radius * wedge.rays[0][1]],
                color="0.3", lw=0.8)
    if full:  # name the lines γᵢ = 0, boundaries of T_C = {γ ≥ 0}, a cone of every law
        to_y = np.linalg.inv(wedges[0].frame)
        for g, name in (([1, 0], "γ₂ = 0"), ([0, 1], "γ₁ = 0")):
            d = to_y @ np.array(g, dtype=float)
            d *= radius / np.linalg.norm(d)
            ax.annotate(name, d, xytext=6 * d / radius, textcoords="offset points",
                        fontsize=8, color="0.3", ha="left" if d[0] > 0.01 else "center",
                        va="bottom" if d[1] >= 0 else "top")
    if gamma is not None:
        g_minus, g_plus = gamma
        ax.plot(*g_minus, "s", color="black", ms=6)
        ax.annotate("γ⁻", g_minus, xytext=(6, 4), textcoords="offset points", fontsize=10)
        ax.annotate("", g_plus, xytext=g_minus,
                    arrowprops={"arrowstyle": "->", "color": "black", "lw": 1.6})
        ax.plot(*g_plus, "*", color="crimson", ms=12)
        ax.annotate("γ⁺", g_plus, xytext=(6, 4), textcoords="offset points", fontsize=10)
    lim = 1.15 * radius
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("y₁: G⁻¹-orthonormal coordinate of the γ⁻ plane (γ = F y, FᵀG⁻¹F = I)",
                  fontsize=9)
    ax.set_ylabel("y₂: G⁻¹-orthonormal coordinate (γᵀG⁻¹γ = y₁² + y₂² in the plane)",
                  fontsize=9)
    ax.set_title(title if title is not None else
                 "Sector law, 3 equal balls: γ⁺ = Q γ⁻ on each cone (u⁺ = sort(u⁻));\n"
                 "in the kinetic metric G⁻¹ every cone is 60° and every Q an isometry.\n"
                 "dots: sample γ⁻, crosses: their images γ⁺ (all in γ ≥ 0)", fontsize=10)
