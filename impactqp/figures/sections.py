"""Figures of S and of the sector law from Python (docs/theory.md §2–§6, §10): the section of
the admissible set S through u⁻ by a plane, with the u⁺ of the laws marked
(:func:`plot_admissible`), and the cones of the sector or reflection law cut by a plane of
γ⁻ (:func:`plot_sectors`), for any number of contacts or balls.

Both return a pyplot-free :class:`matplotlib.figure.Figure` and write it when given a path
(``.png``, ``.svg`` or ``.pdf``). matplotlib is an optional extra (``pip install
'impactqp[plot]'``), imported only when a figure is drawn.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..base.arrays import as_array, as_count
from ..base.figure import figure_format, new_figure, save_figure
from ..errors import InputError, SectorLawError
from ..laws.base import ImpactLaw
from ..laws.pipeline import solve
from ..laws.reflection import ReflectionLaw
from ..laws.sector import MASS_RTOL, SectorLaw
from ..model import admissible
from ..model.admissible import AdmissibleSet
from ..model.builders import chain, newtons_cradle, require_chain
from ..model.problem import ImpactProblem
from ..tables.reflection_table import reflection_law_table
from ..tables.sector_table import MAX_TABLE_BALLS, sector_law_table, sector_velocity_map
from .cone_section import cone_section
from .geometry2d import plane_picture
from .plots import draw_plane, draw_sectors

NAMED = {"sector": SectorLaw, "reflection": ReflectionLaw}
"""Laws :func:`plot_admissible` takes by name."""
DEFAULT_LAWS = ("sector", "reflection")
"""The laws marked by default, where they are defined (Moreau's half-line is always drawn)."""


def _law(entry: Any) -> ImpactLaw:
    if isinstance(entry, ImpactLaw):
        return entry
    if isinstance(entry, str) and entry in NAMED:
        return NAMED[entry]()
    raise InputError(f"laws must hold impact laws (iq.Newton(e=1), …) or the names "
                     f"{sorted(NAMED)}, got {entry!r}")


def _label(law: ImpactLaw) -> str:
    title = getattr(law, "title", "") or repr(law)
    return f"{title.removeprefix('the ')} u⁺"


def _problem_of(S: Any) -> ImpactProblem:
    if isinstance(S, AdmissibleSet):
        if S.mu is not None:
            raise InputError("the picture of S is of frictionless contacts; draw "
                             "problem.normal_problem().admissible_set() for the frictionless S")
        return S.problem
    if isinstance(S, ImpactProblem):
        return S
    raise InputError(f"S must be an AdmissibleSet (problem.admissible_set()) or an "
                     f"ImpactProblem, got {type(S).__name__}")


def law_marks(problem: ImpactProblem, laws: Sequence[Any]) -> tuple[dict[str, np.ndarray],
                                                                    list[str]]:
    """The u⁺ of each law that applies to ``problem``, by label, and a note for each that
    does not (the sector law on unequal masses, say), saying why."""
    marks, notes = {}, []
    for entry in laws:
        law = _law(entry)
        try:
            marks[_label(law)] = solve(problem, law).u_plus
        except SectorLawError as err:
            reason = str(err).split(":")[0].split(";")[0].split(", got")[0]
            notes.append(f"{_label(law).removesuffix(' u⁺')}: not defined here\n({reason})")
    return marks, notes


def plot_admissible(S: Any, path: str | Path | None = None, *,
                    laws: Sequence[Any] = DEFAULT_LAWS,
                    candidates: Mapping[str, ArrayLike] | None = None, plane: Any = None,
                    title: str = "", plane_name: str | None = None) -> Any:
    """Draw the section of S = (u⁻ + N) ∩ T_C ∩ B(0, ‖u⁻‖) through u⁻ by a plane, for any
    number of contacts, with Moreau's half-line and the u⁺ of the laws marked
    (docs/theory.md §2–§5).

    The section is exact (:func:`~impactqp.figures.geometry2d.plane_picture`): the
    half-planes of T_C, the trace of u⁻ + N and the energy disc, in M-orthonormal
    coordinates of the plane, where the energy ball is a circle and the angle α between a
    u⁺ and Moreau's half-line is the one seen on paper.

    Parameters
    ----------
    S : AdmissibleSet or ImpactProblem
        A frictionless S (``problem.admissible_set()``) or its problem.
    path : str or Path, optional
        Where to write the figure (``.png``, ``.svg`` or ``.pdf``).
    laws : sequence of ImpactLaw or str
        Laws whose u⁺ is marked, where they are defined: ``"sector"``, ``"reflection"`` or
        any law object (``iq.Newton(e=1.0)``); a law that is not defined for the problem
        (the sector law on unequal masses) is named in the legend with the reason.
    candidates : mapping of label → (n,) array_like, optional
        Further velocities to mark; each must be kinetically compatible.
    plane : (2, n) array_like, optional
        Two velocity directions: the plane is u⁻ + their span. Default: the plane through
        u⁻ of Moreau's half-line and the first marked u⁺ off it (for two independent
        contacts, the plane u⁻ + range(M⁻¹W), which holds S whole).
    title : str
        Axes title (default: what is drawn).
    plane_name : str, optional
        How the axis labels name the plane.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InputError
        A frictional S, a problem with no approaching contact, a plane that misses S, a
        candidate that is not kinetically compatible, an unknown suffix.
    OptionalDependencyError
        matplotlib is missing.
    """
    if path is not None:
        figure_format(path)
    problem = _problem_of(S)
    marks, notes = law_marks(problem, laws) if problem.contact_dim == 1 else ({}, [])
    marks.update(candidates or {})
    picture = plane_picture(problem, marks, plane=plane)
    st = problem.structure
    whole = plane is None and st.m == 2 and np.linalg.matrix_rank(
        np.asarray(st.W.todense() if hasattr(st.W, "todense") else st.W)) == 2
    if plane_name is None:
        plane_name = "the plane u⁻ + range(M⁻¹W)" if whole else "the plane drawn"
    if not title:
        title = "S = (u⁻ + N) ∩ T_C ∩ B(0, ‖u⁻‖) " + (
            "in the plane u⁻ + range(M⁻¹W)" if whole else
            f"cut by a plane through u⁻ ({st.m} contacts)")
    fig = new_figure(6.4, 7.4 + 0.3 * (len(marks) + 2 * len(notes)))  # room for the legend
    draw_plane(picture, fig.add_subplot(), title, plane=plane_name, notes=notes)
    if path is not None:
        save_figure(fig, path)
    return fig


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
    figure_format(path)
    p = newtons_cradle(3, v=v)
    plot_admissible(p, path, laws=(), candidates={
        "sector law u⁺ = (0, 0, v)": sector_velocity_map(p.u_minus)},
        title=f"3-ball Newton's cradle, u⁻ = (v, 0, 0), v = {v:g}: the plane u₁ + u₂ + u₃ = v",
        plane_name="the plane u₁+u₂+u₃ = v")
    return Path(path)


def _table(masses: np.ndarray, left_wall: bool, right_wall: bool) -> Any:
    """The sector law's table for equal free balls, the reflection law's otherwise
    (:class:`SectorLawError` naming the masses that would work when it has none)."""
    equal = np.ptp(masses) <= MASS_RTOL * masses.max()
    if equal and not (left_wall or right_wall) and masses.size <= MAX_TABLE_BALLS:
        return sector_law_table(int(masses.size), float(masses[0]))
    return reflection_law_table(masses, left_wall=left_wall, right_wall=right_wall)


def plot_sectors(problem: ImpactProblem | None = None, path: str | Path | None = None, *,
                 n_balls: int = 3, masses: ArrayLike | None = None, plane: Any = None,
                 title: str | None = None) -> Any:
    """Draw the cones of the sector law (equal balls, docs/theory.md §6) or of the reflection
    law (masses whose contact angles are 180°/k, docs/theory.md §10) cut by a plane of γ⁻
    through 0, with γ⁻ ↦ γ⁺ on each cone.

    With three balls γ-space is the plane and the figure shows every cone; with more it
    shows the section by ``plane`` — by default the plane of a γ⁻ and its image γ⁺ (the
    problem's, or the cradle's u⁻ = (1, 0, …, 0)), so that the impact drawn lies in it.
    Coordinates are G⁻¹-orthonormal, where the law's cones have their true angles.

    Parameters
    ----------
    problem : ImpactProblem, optional
        A chain (``iq.chain``, ``iq.newtons_cradle``): its masses and walls choose the law,
        its γ⁻ = Wᵀu⁻ is drawn with its image.
    path : str or Path, optional
        Where to write the figure (``.png``, ``.svg`` or ``.pdf``).
    n_balls : int
        Equal balls, when neither ``problem`` nor ``masses`` is given.
    masses : (N,) array_like, optional
        Ball masses of a free chain, when no problem is given.
    plane : (2, N − 1) array_like, optional
        Two directions of γ-space spanning the plane.
    title : str, optional
        Axes title (default: the law, the masses and the plane).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    SectorLawError
        Masses for which no continuous elastic law exists (the message gives the contact
        angles and the masses that would make one): draw their S with
        :func:`plot_admissible`.
    SectorTableTooLarge
        More cones than a table holds.
    InputError
        Not a chain, a bad plane, an unknown suffix.
    OptionalDependencyError
        matplotlib is missing.
    """
    if path is not None:
        figure_format(path)
    left = right = False
    gamma = None
    if isinstance(problem, (str, Path)):
        raise InputError(f"plot_sectors takes a chain problem first; give the output file as "
                         f"path={str(problem)!r}")
    if problem is not None:
        info = require_chain(problem, "picture of the sector law")
        weights, left, right = info.masses, info.left_wall, info.right_wall
        gamma = np.asarray(problem.W.T @ problem.u_minus, dtype=float)
    elif masses is not None:
        weights = as_array("masses", masses, ndim=1)
        if weights.size < 3 or not np.all(weights > 0):
            raise InputError(f"masses must be at least 3 positive numbers, got {weights}")
    else:
        weights = np.ones(as_count("n_balls", n_balls, minimum=3))
    table = _table(np.asarray(weights, dtype=float), left, right)
    m = table.G.shape[0]
    if gamma is None and m > 2:
        cradle = chain(weights, np.eye(weights.size)[0], sparse=False)
        gamma = np.asarray(cradle.W.T @ cradle.u_minus, dtype=float)
    if gamma is not None and not np.any(gamma):
        gamma = None if m == 2 else np.eye(m)[0]
    if plane is None and m > 2:
        image = table.apply(gamma)
        rest = image - (image @ gamma) / (gamma @ gamma) * gamma
        plane = [gamma, image if np.linalg.norm(rest) > 1e-9 * np.linalg.norm(image)
                 else np.eye(m)[int(np.argmin(np.abs(gamma)))]]
    wedges = cone_section(table, plane)
    marked = None
    if gamma is not None:
        F = wedges[0].frame
        Ginv = np.linalg.inv(table.G)
        y_minus, y_plus = F.T @ Ginv @ gamma, F.T @ Ginv @ table.apply(gamma)
        scale = 0.8 / max(np.linalg.norm(y_minus), 1e-300)
        marked = (scale * y_minus, scale * y_plus)
    if title is None:
        name = "Sector law" if hasattr(table, "mass") else f"Reflection law ({table.group.name})"
        shown = ", ".join(f"{w:.4g}" for w in np.asarray(weights)[:8])
        title = (f"{name}, {np.asarray(weights).size} balls, masses ({shown}): "
                 f"γ⁺ = Q γ⁻ on each cone\n"
                 + ("in the kinetic metric G⁻¹ every Q is an isometry; dots: sample γ⁻, "
                    "crosses: their images γ⁺" if m == 2 else
                    f"section of {m}-dimensional γ-space by the plane of γ⁻ and γ⁺; "
                    "black: γ⁻ ↦ γ⁺"))
    fig = new_figure(7.0, 7.0)
    draw_sectors(wedges, fig.add_subplot(), title=title, gamma=marked)
    if path is not None:
        save_figure(fig, path)
    return fig


admissible.DRAWING[0] = plot_admissible  # S.plot(...) draws by it
