"""The cones of a piecewise-linear impact law — the sector law (docs/theory.md §6) or the
reflection law (docs/theory.md §10) — cut by a plane of contact velocities γ through 0, as
arrays for :func:`impactqp.figures.plots.draw_sectors`.

The plane is drawn in coordinates orthonormal for the kinetic metric G⁻¹ of γ-space
(:func:`sector_frame`), where the cones have their true angles (60° for three equal balls)
and every map γ⁻ ↦ Qγ⁻ is an isometry.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..errors import InputError
from ..tables.sector_table import sector_law_table
from .plane_cone import kinetic_frame


@dataclass(frozen=True)
class Wedge:
    """The trace of one cone of a piecewise-linear law (the sector law, docs/theory.md §6,
    or the reflection law, docs/theory.md §10) in a plane of γ-space, drawn as a circular
    sector.

    All points are in the G⁻¹-orthonormal coordinates y of the plane (γ = ``frame @ y``);
    ``sample`` is a γ⁻ inside the cone and ``image`` its γ⁺ = Q γ⁻ projected on the plane,
    ``off_plane`` the G⁻¹-distance of γ⁺ from the plane relative to ‖γ⁻‖ (0 when γ-space
    is the plane); ``rays`` are the unit boundary rays, counter-clockwise.
    """

    label: str
    Q: np.ndarray
    text: str
    polygon: np.ndarray
    anchor: np.ndarray
    sample: np.ndarray
    image: np.ndarray
    frame: np.ndarray
    off_plane: float = 0.0
    rays: tuple[np.ndarray, np.ndarray] | None = None


def _matrix_text(Q: np.ndarray) -> str:
    """``Q = [a b; c d]`` with 4 digits, round-off below 10⁻¹² of the largest entry shown 0."""
    Q = np.where(np.abs(Q) <= 1e-12 * np.abs(Q).max(), 0.0, Q)
    return "Q = [" + "; ".join(" ".join(f"{v + 0.0:.4g}" for v in row) for row in Q) + "]"


def sector_frame(G: ArrayLike) -> np.ndarray:
    """The lower Cholesky factor L of the Delassus matrix G = LLᵀ.

    Coordinates y with γ = L y are orthonormal in the metric G⁻¹ of the γ plane
    (γᵀG⁻¹γ = yᵀy), which is the kinetic metric of the velocities u = M⁻¹WG⁻¹γ: in them
    the angles of the sector law's cones are the true ones (60° for three equal balls) and
    every map γ⁻ ↦ Qγ⁻ is an isometry.

    Parameters
    ----------
    G : (m, m) array_like
        Symmetric positive definite.

    Returns
    -------
    ndarray
        L, shape (m, m).
    """
    return np.linalg.cholesky(np.asarray(G, dtype=float))


def _g_frame(G: np.ndarray, plane: Any) -> np.ndarray:
    """G⁻¹-orthonormal columns F (γ = F y) of a plane of γ-space: the Cholesky factor L
    when γ-space is the plane itself and no plane is given, else Gram–Schmidt in G⁻¹ of the
    two directions of ``plane``."""
    m = G.shape[0]
    if plane is None and m == 2:
        return sector_frame(G)
    pair = np.asarray(plane, dtype=float)
    if pair.shape != (2, m) or not np.isfinite(pair).all():
        raise InputError(f"plane must be two directions of γ-space (length {m}), as a (2, {m}) "
                         f"array, got shape {pair.shape}")
    frame = kinetic_frame(np.linalg.inv(G), list(pair))
    if frame is None:
        raise InputError("plane: the two directions of γ are parallel (or zero); give two "
                         "independent directions")
    return frame


def cone_section(table: Any, plane: Any = None, *, radius: float = 1.0,
                 sample_radius: float = 0.45) -> list[Wedge]:
    """The cones of a piecewise-linear law's table cut by a plane of γ-space through 0
    (docs/theory.md §6, §10): one circular sector per cone that the plane meets in more
    than a ray, each with a sample γ⁻ and its image γ⁺ = Qγ⁻.

    The section is exact: the plane meets the hyperplanes bounding the cones in rays, found
    in closed form; between two neighbouring rays one cone holds the whole angle (the one
    holding its bisector).

    Parameters
    ----------
    table : SectorTable or ReflectionTable
        From :func:`~impactqp.tables.sector_law_table` or
        :func:`~impactqp.tables.reflection_law_table`.
    plane : (2, m) array_like, optional
        Two directions of γ-space spanning the plane (default: γ-space itself when m = 2).
    radius : float
        Radius of the drawn sectors.
    sample_radius : float
        Typical distance of the sample points from the origin, as a fraction of ``radius``
        (each cone's sample lies at an angle and a distance of its own, so that no two images
        coincide).

    Returns
    -------
    list of Wedge
        In counter-clockwise order, in the G⁻¹-orthonormal coordinates y of the plane
        (γ = ``frame @ y``); ``image`` is the projection of γ⁺ on the plane and
        ``off_plane`` says how far γ⁺ lies from it (relative, in G⁻¹).

    Raises
    ------
    InputError
        A plane that is not two independent directions of γ-space.
    """
    G = np.asarray(table.G, dtype=float)
    F = _g_frame(G, plane)
    Ginv = np.linalg.inv(G)
    to_y = F.T @ Ginv  # coordinates of the G⁻¹-projection on the plane
    rows = np.concatenate([c.inequalities for c in table.cones]) @ F  # each row's trace
    rows = rows[np.linalg.norm(rows, axis=1) > 1e-12 * np.abs(rows).max()]
    cuts = np.mod(np.concatenate([np.arctan2(-rows[:, 0], rows[:, 1]),
                                  np.arctan2(rows[:, 0], -rows[:, 1])]), 2 * np.pi)
    cuts = np.unique(np.round(cuts, 12))
    if cuts.size == 0:
        cuts = np.array([0.0])
    ends = np.append(cuts[1:], cuts[0] + 2 * np.pi)
    mids = 0.5 * (cuts + ends)
    index = table.find_cones(np.column_stack([np.cos(mids), np.sin(mids)]) @ F.T)
    pieces: list[list[float]] = []  # [cone, start, stop], neighbours of one cone merged
    for k, start, stop in zip(index, cuts, ends):
        if pieces and pieces[-1][0] == k:
            pieces[-1][2] = stop
        else:
            pieces.append([int(k), start, stop])
    if len(pieces) > 1 and pieces[0][0] == pieces[-1][0]:
        pieces[0][1] = pieces.pop()[1] - 2 * np.pi
    count = len(pieces)
    wedges = []
    for j, (k, start, stop) in enumerate(pieces):
        cone = table.cones[k]
        r1 = np.array([np.cos(start), np.sin(start)])
        r2 = np.array([np.cos(stop), np.sin(stop)])
        mid = 0.5 * (start + stop)
        polygon = np.vstack([[0.0, 0.0], radius * np.column_stack(
            [np.cos(t := np.linspace(start, stop, 40)), np.sin(t)])])
        angle = start + (j + 0.5) / count * (stop - start)
        sample = sample_radius * radius * (0.75 + 0.6 * j / count) * np.array(
            [np.cos(angle), np.sin(angle)])
        gamma_plus = cone.Q @ (F @ sample)
        image = to_y @ gamma_plus
        off = float(np.sqrt(max((d := gamma_plus - F @ image) @ Ginv @ d, 0.0))
                    / max(np.linalg.norm(sample), 1e-300))
        text = f"{cone.label}\n{_matrix_text(cone.Q)}" if G.shape[0] == 2 else cone.label
        wedges.append(Wedge(label=cone.label, Q=cone.Q, text=text, polygon=polygon,
                            anchor=0.72 * radius * np.array([np.cos(mid), np.sin(mid)]),
                            sample=sample, image=image, frame=F, off_plane=off,
                            rays=(r1, r2)))
    return wedges


def sector_picture(radius: float = 1.0, sample_radius: float = 0.45) -> list[Wedge]:
    """The six cones of the (γ₁⁻, γ₂⁻) plane for three equal balls, each with its Q and
    one sample point mapped by the law (docs/theory.md §6): :func:`cone_section` of
    ``sector_law_table(3)``.

    The plane is drawn in G⁻¹-orthonormal coordinates (:func:`sector_frame`), so each cone is
    a 60° circular sector of radius ``radius`` and every image lies as far from the origin as
    its sample.

    Returns
    -------
    list of Wedge
        One per cone, counter-clockwise.
    """
    return cone_section(sector_law_table(3), radius=radius, sample_radius=sample_radius)
