"""The figure of :mod:`impactqp.verification.compare`: post-impact velocities of Moreau's law,
the sector law and the LZB model, ball by ball, for one or more chains (docs/theory.md §13).

matplotlib is an optional extra (``pip install 'impactqp[plot]'``), imported only when a
figure is drawn, on a bare :class:`matplotlib.figure.Figure` (no pyplot).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..base.figure import figure_format, new_figure, save_figure
from ..errors import InputError
from ..verification.compare import LawComparison

STYLES = {"Moreau ε = 0": ("tab:blue", "s", "--"), "Moreau ε = 1": ("tab:orange", "D", "--"),
          "sector law": ("tab:green", "^", ":"), "LZB": ("crimson", "o", "-")}


def draw_comparison(comparison: LawComparison, ax: Any, title: str = "") -> None:
    """Draw u⁺ of every law against the ball index on ``ax``; the legend says whether each
    u⁺ lies in S (docs/theory.md §2)."""
    n = comparison.problem.n_dof
    balls = np.arange(1, n + 1)
    ax.axhline(0.0, color="0.6", lw=0.8)
    for outcome in comparison.outcomes:
        if outcome.result is None:
            ax.plot([], [], " ", label=f"{outcome.law}: does not apply ({outcome.note})")
            continue
        color, marker, line = STYLES.get(outcome.law, ("black", "x", "-"))
        verdict = "u⁺ ∈ S" if outcome.in_S else "u⁺ ∉ S"
        ax.plot(balls, outcome.u_plus, color=color, marker=marker, ls=line, lw=1.3, ms=6,
                label=f"{outcome.law} ({verdict}, T⁺/T⁻ = {outcome.energy_ratio:.3f})")
    ax.plot(balls, comparison.problem.u_minus, color="0.3", marker="x", ls="none", ms=8,
            label="u⁻ (before)")
    ax.set_xticks(balls)
    ax.set_xlabel("ball")
    ax.set_ylabel("velocity (m/s): after the impact, and u⁻ before")
    ax.legend(fontsize=8, loc="lower right", framealpha=0.9)
    ax.set_title(title, fontsize=10)


def plot_comparison(comparisons: Sequence[LawComparison], path: str | Path,
                    titles: Sequence[str] | None = None) -> Path:
    """Write the velocities of each comparison in its own panel, side by side.

    Parameters
    ----------
    comparisons : sequence of LawComparison
        From :func:`impactqp.verification.compare.compare_chain` or ``compare_laws``.
    path : str or Path
        Output file, ``.png``, ``.svg`` or ``.pdf``.
    titles : sequence of str, optional
        One title per panel.

    Returns
    -------
    Path

    Raises
    ------
    InputError
        No comparison, a wrong suffix, or titles that do not match the panels.
    OptionalDependencyError
        matplotlib is not installed.
    """
    figure_format(path)
    comparisons = list(comparisons)
    if not comparisons or not all(isinstance(c, LawComparison) for c in comparisons):
        raise InputError("comparisons must be a non-empty sequence of LawComparison")
    titles = [""] * len(comparisons) if titles is None else list(titles)
    if len(titles) != len(comparisons):
        raise InputError(f"titles must have one entry per comparison ({len(comparisons)}), "
                         f"got {len(titles)}")
    fig = new_figure(6.4 * len(comparisons), 5.2)
    axes = fig.subplots(1, len(comparisons), squeeze=False)[0]
    for comparison, ax, title in zip(comparisons, axes, titles):
        draw_comparison(comparison, ax, title)
    return save_figure(fig, path)
