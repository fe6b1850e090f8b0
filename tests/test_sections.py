"""S and the sector law drawn from Python for any number of contacts: the section of S through
u⁻ checked point by point by exact membership (inside, on the boundary, against a grid), the
laws' u⁺ where they are defined, and the cones of the sector and reflection laws cut by a
plane of γ."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.figures.cone_section import cone_section
from impactqp.figures.geometry2d import plane_picture
from impactqp.figures.plane_cone import cone_of_directions
from impactqp.tables import reflection_law_table, sector_law_table
from impactqp.tables.sector_table import sector_gamma_map

pytest.importorskip("matplotlib")
pytestmark = pytest.mark.filterwarnings("error")  # no warning escapes a figure

HEAVY = iq.chain([1.0, 1.0, 1.0, 3.0], [1.0, 0.0, 0.0, 0.0])
"""A 4-ball cradle with one heavy ball: three contacts, no sector or reflection law."""


def _inside(polygon: np.ndarray, x: np.ndarray) -> float:
    """Signed distance of x from the boundary of a convex counter-clockwise polygon
    (positive inside)."""
    a, b = polygon, np.roll(polygon, -1, axis=0)
    edge = b - a
    normal = np.column_stack([-edge[:, 1], edge[:, 0]]) / np.linalg.norm(edge, axis=1)[:, None]
    return float(np.min(np.einsum("ij,ij->i", x - a, normal)))


def _ccw(polygon: np.ndarray) -> np.ndarray:
    x, y = polygon.T
    return polygon if x @ np.roll(y, -1) - y @ np.roll(x, -1) > 0 else polygon[::-1]


@pytest.mark.parametrize("problem", [HEAVY, iq.newtons_cradle(5), iq.random_impact(6, 4, seed=3)])
def test_the_section_is_S_point_by_point(problem):
    S = problem.admissible_set()
    pic = plane_picture(problem)
    poly = _ccw(pic.admissible)
    assert len(poly) > 10
    # every vertex in S, by exact membership
    assert all(S.contains(u) for u in pic.lift(poly))
    # every vertex on S's boundary in the plane: a step outwards leaves S
    centre = poly.mean(axis=0)
    assert S.contains(pic.lift(centre))
    step = 1e-6 * pic.radius
    outward = (poly - centre) / np.linalg.norm(poly - centre, axis=1)[:, None]
    assert not any(S.contains(u) for u in pic.lift(poly + step * outward))
    # each vertex lies on the energy circle or on the line of one of the exact half-planes
    for x in poly:
        on_circle = abs(np.linalg.norm(x) - pic.radius) <= 1e-9 * pic.radius
        on_line = min(abs(n @ x - c) / np.linalg.norm(n) for n, c in pic.halfplanes)
        assert on_circle or on_line <= 1e-9 * pic.radius
        assert all(n @ x - c >= -1e-9 * pic.radius * np.linalg.norm(n)
                   for n, c in pic.halfplanes)
    # a grid of the plane: exact membership agrees with the polygon away from its boundary
    g = np.linspace(-pic.half_width, pic.half_width, 23)
    agree = checked = 0
    for x in g:
        for y in g:
            d = _inside(poly, np.array([x, y]))
            if abs(d) < 1e-3 * pic.radius:
                continue
            checked += 1
            agree += bool(S.contains(pic.lift([x, y]))) == (d > 0)
    assert checked > 400 and agree == checked


def test_the_default_plane_holds_moreaus_half_line_and_the_sector_point():
    n = 4
    p = iq.newtons_cradle(n)
    pic = plane_picture(p, {"sector": iq.sector_law(p).u_plus})
    for eps, x in pic.moreau_marks.items():
        np.testing.assert_allclose(pic.lift(x), iq.moreau(p, eps=eps).u_plus, atol=1e-12)
    (cand,) = pic.candidates
    assert cand.off_plane < 1e-12
    np.testing.assert_allclose(pic.lift(cand.point), iq.sector_law(p).u_plus, atol=1e-12)
    # docs/theory.md §6: α = arccos √(n / (2(n − 1))) on the n-ball cradle
    assert cand.alpha_deg == pytest.approx(np.degrees(np.arccos(np.sqrt(n / (2 * (n - 1))))),
                                           abs=1e-9)
    assert np.linalg.norm(cand.point) == pytest.approx(pic.radius)  # energy conserved


def test_one_contact_gives_moreaus_segment():
    p = iq.chain([1.0, 2.0], [1.0, 0.0])
    pic = plane_picture(p)
    assert pic.reaction_trace.kind == "ray" and pic.admissible.shape == (2, 2)
    ends = sorted(pic.lift(pic.admissible), key=lambda u: u[0])
    np.testing.assert_allclose(ends[0], iq.moreau(p, eps=1.0).u_plus, atol=1e-12)
    np.testing.assert_allclose(ends[1], iq.moreau(p, eps=0.0).u_plus, atol=1e-12)


def test_a_plane_that_misses_S_is_refused():
    # through u⁻ along the first contact only: the other two keep approaching or are pushed
    W = np.asarray(HEAVY.W)
    with pytest.raises(iq.InputError, match="does not meet"):
        plane_picture(HEAVY, plane=[W[:, 0], np.eye(4)[3]])
    with pytest.raises(iq.InputError, match="parallel"):
        plane_picture(HEAVY, plane=[W[:, 0], 2 * W[:, 0]])


def test_cone_of_directions():
    assert cone_of_directions(np.array([0.3])).kind == "ray"
    wedge = cone_of_directions(np.array([0.0, 1.0, 0.5]))
    assert wedge.kind == "wedge"
    np.testing.assert_allclose(wedge.first, [1.0, 0.0])
    np.testing.assert_allclose(wedge.last, [np.cos(1.0), np.sin(1.0)])
    assert cone_of_directions(np.array([0.0, np.pi])).kind == "half-plane"
    assert cone_of_directions(np.array([0.0, 2.0, 4.0])).kind == "plane"
    assert cone_of_directions(np.array([])).kind == "point"


def test_plot_admissible_of_a_heavy_cradle(tmp_path):
    out = tmp_path / "S.svg"
    fig = iq.plot_admissible(HEAVY.admissible_set(), out, laws=("sector", iq.Newton(e=1.0)))
    assert out.read_bytes().lstrip().startswith(b"<?xml") and len(fig.axes) == 1
    (ax,) = fig.axes
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(lab.startswith("local Newton law u⁺ (α = ") for lab in labels)
    assert any(lab.startswith("sector law: not defined here") and "equal masses" in lab
               for lab in labels)
    pic = plane_picture(HEAVY)
    assert ax.get_xlim() == pytest.approx((-pic.half_width, pic.half_width))
    assert "M-orthonormal" in ax.get_xlabel()
    with pytest.raises(iq.InputError, match="frictionless"):
        iq.plot_admissible(iq.friction.sphere_on_plane(1.0, 0.5, [1.0, -1.0, 0.0]).admissible_set(
            mu=0.5))
    with pytest.raises(iq.InputError, match="AdmissibleSet"):
        iq.plot_admissible("S")


def test_sector_section_of_four_balls():
    table = sector_law_table(4)
    p = iq.newtons_cradle(4)
    gamma = np.asarray(p.W.T @ p.u_minus)
    image = sector_gamma_map(gamma)
    wedges = cone_section(table, [gamma, image])
    spans = [np.arctan2(a[0] * b[1] - a[1] * b[0], a @ b) % (2 * np.pi)
             for a, b in (w.rays for w in wedges)]
    assert sum(spans) == pytest.approx(2 * np.pi)
    Ginv = np.linalg.inv(table.G)
    F = wedges[0].frame
    np.testing.assert_allclose(F.T @ Ginv @ F, np.eye(2), atol=1e-12)
    for w in wedges:
        cone = next(c for c in table.cones if c.label == w.label)
        mid = F @ (w.rays[0] + w.rays[1])
        assert cone.contains(mid)
        # each boundary ray lies on a hyperplane uᵢ = uⱼ of the cone
        assert np.min(np.abs(cone.inequalities @ (F @ w.rays[0]))) < 1e-9
    fig = iq.plot_sectors(p)
    (ax,) = fig.axes
    assert "4 balls" in ax.get_title() and len(ax.patches) == len(wedges)  # one fill each
    y_minus, y_plus = F.T @ Ginv @ gamma, F.T @ Ginv @ image
    arrows = [a for a in ax.texts if a.get_text() == "" and hasattr(a, "arrow_patch")]
    assert arrows  # γ⁻ ↦ γ⁺ drawn in the plane
    assert np.linalg.norm(y_minus) == pytest.approx(np.linalg.norm(y_plus))  # isometry


def test_reflection_law_cones_and_a_refusal(tmp_path):
    masses = [1.0, np.sqrt(2.0) - 1.0, 1.0]  # 45°: the group B₂ of 8 elements
    wedges = cone_section(reflection_law_table(masses))
    assert len(wedges) == 8
    for w in wedges:
        assert np.degrees(np.arccos(np.clip(w.rays[0] @ w.rays[1], -1, 1))) == \
            pytest.approx(45.0)
    iq.plot_sectors(masses=masses, path=tmp_path / "r.png")
    assert (tmp_path / "r.png").read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(iq.errors.SectorLawError, match="no continuous elastic law"):
        iq.plot_sectors(HEAVY)
    with pytest.raises(iq.InputError, match="path='s.png'"):
        iq.plot_sectors("s.png")
    with pytest.raises(iq.InputError, match="at least 3 positive"):
        iq.plot_sectors(masses=[1.0, -1.0, 1.0])


def test_s_draws_itself_as_plot_admissible_does(tmp_path):
    S = HEAVY.admissible_set()
    by_method = S.plot(tmp_path / "m.png", laws=("sector",))
    by_function = iq.plot_admissible(S, tmp_path / "f.png", laws=("sector",))
    (a,), (b,) = by_method.axes, by_function.axes
    assert [t.get_text() for t in a.get_legend().get_texts()] == \
        [t.get_text() for t in b.get_legend().get_texts()]
    assert len(a.lines) == len(b.lines) > 0
    for la, lb in zip(a.lines, b.lines):
        np.testing.assert_array_equal(la.get_xydata(), lb.get_xydata())
    assert (tmp_path / "m.png").read_bytes()[:4] == b"\x89PNG"
