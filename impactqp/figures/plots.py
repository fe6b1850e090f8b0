"""Figures of S (docs/theory.md §2–§5) and of the sector law (docs/theory.md §6), drawn from
:mod:`impactqp.geometry2d`.

matplotlib is an optional extra (``pip install 'impactqp[plot]'``), imported only here and
only when a figure is drawn. Figures are built on a bare :class:`matplotlib.figure.Figure`
(no pyplot, no global state), so they render headless; the format follows the suffix of the
output file (``.png`` or ``.svg``).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InputError, OptionalDependencyError
from ..model.builders import newtons_cradle
from ..model.problem import ImpactProblem
from ..tables.sector_table import sector_velocity_map
from .geometry2d import PlanePicture, Wedge, plane_picture, sector_picture

FORMATS = {".png": "png", ".svg": "svg"}
DPI = 100


def _figure(size: float = 6.4) -> Any:
    """A pyplot-free matplotlib Figure, or a clear error naming the extra to install."""
    try:
        from matplotlib.figure import Figure
    except ImportError:
        raise OptionalDependencyError("figures need matplotlib: pip install 'impactqp[plot]'") \
            from None
    return Figure(figsize=(size, size), dpi=DPI, layout="constrained")


def _format(path: str | Path) -> str:
    fmt = FORMATS.get(Path(path).suffix.lower())
    if fmt is None:
        raise InputError(f"figure file must end in one of {sorted(FORMATS)}, got "
                         f"{Path(path).name!r}")
    return fmt


def _save(fig: Any, path: str | Path) -> Path:
    fmt = _format(path)
    fig.savefig(path, format=fmt, metadata={"Software": None} if fmt == "png" else {"Date": None})
    return Path(path)


def draw_plane(picture: PlanePicture, ax: Any, title: str = "") -> None:
    """Draw S, u⁻ + N, T_C, the energy circle, Moreau's half-line and the candidates
    (docs/theory.md §5)."""
    from matplotlib.colors import to_rgba

    def fill(poly: np.ndarray, color: str, alpha: float, label: str) -> None:
        ax.fill(poly[:, 0], poly[:, 1], fc=to_rgba(color, alpha), ec=color, lw=1.3, label=label)

    fill(picture.tangent_cone, "tab:orange", 0.15, "T_C (its trace in the plane)")
    fill(picture.reaction_cone, "tab:blue", 0.12, "u⁻ + N")
    fill(picture.admissible, "tab:green", 0.6, "S")
    circle = np.vstack([picture.circle, picture.circle[:1]])
    ax.plot(circle[:, 0], circle[:, 1], ls="--", color="0.35", lw=1.0,
            label="energy circle ‖u‖ = ‖u⁻‖")
    line = picture.moreau_line
    ax.plot(line[:, 0], line[:, 1], color="black", lw=1.4, label="Moreau's half-line")
    for eps, x in picture.moreau_marks.items():
        ax.plot(*x, "o", color="black", ms=5)
        ax.annotate(f"ε = {eps:g}" + (" (z)" if eps == 0 else ""), x, xytext=(-8, 0),
                    textcoords="offset points", ha="right", va="center", fontsize=9)
    ax.plot(*picture.u_minus, "s", color="black", ms=6)
    ax.annotate("u⁻", picture.u_minus, xytext=(6, 4), textcoords="offset points", fontsize=11)
    for cand in picture.candidates:
        ax.plot(*cand.point, "*", color="crimson", ms=13, label=cand.label)
        if len(cand.arc):
            ax.plot(cand.arc[:, 0], cand.arc[:, 1], color="crimson", lw=1.2)
            ax.plot([picture.u_minus[0], cand.point[0]], [picture.u_minus[1], cand.point[1]],
                    color="crimson", lw=0.9, ls=":")
            mid = cand.arc[len(cand.arc) // 2]
            ax.annotate(f"α = {cand.alpha_deg:.1f}°", mid, xytext=(4, -10),
                        textcoords="offset points", color="crimson", fontsize=10)
    h = picture.half_width
    ax.set_xlim(-h, h)
    ax.set_ylim(-h, h)
    ax.set_aspect("equal")
    ax.set_xlabel("x₁ (kinetic metric)")
    ax.set_ylabel("x₂ (kinetic metric)")
    ax.legend(loc="upper left", fontsize=8, framealpha=0.9)
    ax.set_title(title, fontsize=10)


def draw_sectors(wedges: list[Wedge], ax: Any, radius: float = 1.0) -> None:
    """Draw the six cones of the γ⁻ plane with their Q and sample points γ⁻ ↦ γ⁺ (docs/theory.md
    §6)."""
    colors = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]
    for wedge, color in zip(wedges, colors):
        ax.fill(wedge.polygon[:, 0], wedge.polygon[:, 1], color=color, alpha=0.18, lw=0)
        ax.text(*wedge.anchor, wedge.text, ha="center", va="center", fontsize=8)
        ax.plot(*wedge.sample, "o", color=color, ms=5)
        ax.annotate("", wedge.image, xytext=wedge.sample,
                    arrowprops={"arrowstyle": "->", "color": color, "lw": 1.2})
        ax.plot(*wedge.image, "x", color=color, ms=6)
    for direction in ([1, 0], [0, 1], [1, -1]):
        d = radius * np.array(direction, dtype=float) / np.linalg.norm(direction)
        ax.plot([-d[0], d[0]], [-d[1], d[1]], color="0.3", lw=0.8)
    ax.set_xlim(-radius, radius)
    ax.set_ylim(-radius, radius)
    ax.set_aspect("equal")
    ax.set_xlabel("γ₁⁻ = u₂ − u₁")
    ax.set_ylabel("γ₂⁻ = u₃ − u₂")
    ax.set_title("Sector law, 3 equal balls: γ⁺ = Q γ⁻ on each cone (u⁺ = sort(u⁻))\n"
                 "dots: sample γ⁻, crosses: their images γ⁺ (all in γ ≥ 0)", fontsize=10)


def plot_S(problem: ImpactProblem, path: str | Path,
           candidates: Mapping[str, ArrayLike] | None = None, title: str = "") -> Path:
    """Write the picture of S for a problem with two independent contacts (PNG or SVG)."""
    _format(path)
    picture = plane_picture(problem, candidates)
    fig = _figure()
    draw_plane(picture, fig.add_subplot(), title or "S = (u⁻ + N) ∩ T_C ∩ B(0, ‖u⁻‖) in the "
               "plane u⁻ + range(M⁻¹W)")
    return _save(fig, path)


def plot_cradle(path: str | Path, v: float = 1.0) -> Path:
    """Write the picture of docs/theory.md §5: the 3-ball cradle's S, Moreau's half-line and the
    sector-law
    point (0, 0, v) at α = 30°, in the plane u₁ + u₂ + u₃ = v."""
    p = newtons_cradle(3, v=v)
    return plot_S(p, path, {"sector law u⁺ = (0, 0, v)": sector_velocity_map(p.u_minus)},
                  title=f"3-ball Newton's cradle, u⁻ = (v, 0, 0), v = {v:g}: the plane "
                        "u₁ + u₂ + u₃ = v")


def plot_sectors(path: str | Path) -> Path:
    """Write the figure of the six cones of the 3-ball sector law (docs/theory.md §6)."""
    _format(path)
    fig = _figure()
    draw_sectors(sector_picture(), fig.add_subplot())
    return _save(fig, path)
