import sys
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
from impactqp.figures.cone_section import sector_picture
from impactqp.figures.geometry2d import clip, plane_picture
from impactqp.figures.plots import _edges, draw_plane
from impactqp.figures.sections import plot_admissible, plot_cradle, plot_sectors
from impactqp.tables.sector_table import sector_law_table


@pytest.fixture(scope="module")
def cradle():
    p = iq.newtons_cradle(3, v=2.0)
    return p, plane_picture(p, {"sector": [0.0, 0.0, 2.0]})


def test_plane_is_momentum_conserving_and_metric(cradle):
    p, pic = cradle
    np.testing.assert_allclose(pic.basis.T @ p.M @ pic.basis, np.eye(2), atol=1e-12)
    np.testing.assert_allclose(pic.basis.sum(axis=0), 0.0, atol=1e-12)  # u1+u2+u3 = v
    np.testing.assert_allclose(pic.origin, [2 / 3] * 3)
    np.testing.assert_allclose(pic.lift(pic.u_minus), p.u_minus, atol=1e-12)
    assert pic.radius == pytest.approx(np.sqrt(4 - 4 / 3))


def test_moreau_marks_are_moreaus_law(cradle):
    p, pic = cradle
    for eps, x in pic.moreau_marks.items():
        np.testing.assert_allclose(pic.lift(x), iq.moreau(p, eps=eps).u_plus, atol=1e-12)
    assert np.linalg.norm(pic.moreau_marks[1.0]) == pytest.approx(pic.radius, rel=1e-12)
    assert np.linalg.norm(pic.moreau_marks[0.0] - pic.z) < 1e-12
    start, end = pic.moreau_line
    direction = pic.z - pic.u_minus
    d = end - start
    assert abs(d[0] * direction[1] - d[1] * direction[0]) < 1e-12 and d @ direction > 0
    assert np.max(np.abs(end)) == pytest.approx(pic.half_width)


def test_sector_point_is_30_degrees_from_moreau(cradle):
    p, pic = cradle
    (cand,) = pic.candidates
    assert cand.alpha_deg == pytest.approx(30.0, abs=1e-9)
    assert cand.alpha_deg == pytest.approx(iq.classify(p, [0, 0, 2.0]).alpha_deg, abs=1e-9)
    assert np.linalg.norm(cand.point) == pytest.approx(pic.radius)  # on the energy circle
    np.testing.assert_allclose(np.linalg.norm(cand.arc - pic.u_minus, axis=1), 0.3 * pic.radius)


def test_S_polygon_vertices_are_in_S_and_the_region_is_right(cradle):
    p, pic = cradle
    S = p.admissible_set()
    assert all(S.contains(u) for u in pic.lift(pic.admissible))
    # the S region of docs/theory.md §5 is the circular sector between Moreau's half-line and the
    # T_C face
    # through the sector point: area (60° / 360°) π r²
    x, y = pic.admissible.T
    area = 0.5 * abs(x @ np.roll(y, 1) - y @ np.roll(x, 1))
    assert area == pytest.approx(np.pi * pic.radius**2 / 6, rel=1e-3)
    assert all(S.contains(u).kinetic < 1e-12 for u in pic.lift(pic.reaction_cone))
    assert all(S.contains(u).kinematic < 1e-12 for u in pic.lift(pic.tangent_cone))
    assert max(S.contains(u).kinematic for u in pic.lift(pic.reaction_cone)) > 0.1


def test_general_problem_plane():
    p = iq.ImpactProblem([[2.0, 0.3, 0], [0.3, 1.0, 0.1], [0, 0.1, 3.0]],
                         [[-1.0, 0.2], [1.0, -1.0], [0.1, 1.0]], [1.0, -0.5, -0.8])
    pic = plane_picture(p)
    S = p.admissible_set()
    assert len(pic.admissible) > 3 and all(S.contains(u) for u in pic.lift(pic.admissible))
    assert np.linalg.norm(pic.moreau_marks[1.0]) == pytest.approx(pic.radius, rel=1e-12)


@pytest.mark.parametrize("problem, message", [
    (iq.newtons_cradle(3, v=-1.0), "S = {u⁻}"),
    (iq.chain([1.0], [1.0]), "no contact"),
])
def test_undrawable_problems(problem, message):
    with pytest.raises(iq.InputError, match=message):
        plane_picture(problem)


def test_candidate_off_the_plane_is_refused():
    with pytest.raises(iq.InputError, match="not kinetically compatible"):
        plane_picture(iq.newtons_cradle(), {"bad": [1.0, 1.0, 1.0]})


def test_clip_half_plane():
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    np.testing.assert_allclose(clip(square, np.array([1.0, 0.0]), 0.5),
                               [[0.5, 0.0], [1.0, 0.0], [1.0, 1.0], [0.5, 1.0]])


def test_sector_picture_data():
    wedges = sector_picture()
    assert len(wedges) == 6 and len({w.label for w in wedges}) == 6
    table = sector_law_table(3)
    cones = {c.label: c for c in table.cones}
    for w in wedges:
        cone = cones[w.label]
        np.testing.assert_allclose(w.frame @ w.frame.T, table.G, atol=1e-12)  # G = LLᵀ

        def gamma(y, w=w):
            return w.frame @ np.asarray(y).T

        assert cone.contains(gamma(w.sample)) and cone.contains(gamma(w.anchor))
        assert all(cone.contains(gamma(y)) for y in w.polygon)
        np.testing.assert_allclose(gamma(w.image), cone.Q @ gamma(w.sample), atol=1e-12)
        assert np.all(gamma(w.image) >= -1e-12)
        assert w.label in w.text and "Q = [" in w.text
        # G⁻¹-orthonormal coordinates: every cone is 60°, every Q an isometry
        a, b = w.polygon[1], w.polygon[-1]
        assert np.degrees(np.arccos(a @ b)) == pytest.approx(60.0)
        assert np.linalg.norm(w.image) == pytest.approx(np.linalg.norm(w.sample))
    images = np.array([w.image for w in wedges])
    assert min(np.linalg.norm(images[i] - images[j]) for i in range(6)
               for j in range(i)) > 0.02  # no two images drawn on top of each other


def test_edges_leave_out_the_view_border():
    square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    assert len(_edges(square, 1.0)) == 0
    wedge = np.array([[0.0, 0.0], [1.0, -1.0], [1.0, 1.0]])  # one side on the border x = 1
    path = _edges(wedge, 1.0)
    segments = [s for s in np.split(path, np.flatnonzero(np.isnan(path[:, 0])))
                if len(s[~np.isnan(s[:, 0])]) == 2]
    assert len(segments) == 2


def test_legend_shows_the_colours_of_the_regions():
    from matplotlib.colors import to_rgba
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    draw_plane(plane_picture(iq.newtons_cradle(3)), ax)
    fills = {to_rgba(p.get_facecolor()) for p in ax.patches if p.get_fill()}
    legend = {h.get_label(): h for h in ax.get_legend().legend_handles}
    for label in ("u⁻ + N", "S"):
        face = to_rgba(legend[label].get_facecolor())
        assert face[3] == 1.0 and face in fills  # opaque and the colour drawn
    tangent = legend["T_C (its trace in the plane)"]
    assert tangent.get_hatch() and any(p.get_hatch() == tangent.get_hatch() for p in ax.patches)
    assert all(to_rgba(p.get_facecolor())[3] in (0.0, 1.0) for p in ax.patches)  # no blending
    assert "M-orthonormal" in ax.get_xlabel() and "M-orthonormal" in ax.get_ylabel()


def _check_file(path, fmt):
    if not isinstance(path, Path):  # a figure: the caller wrote it
        return
    data = path.read_bytes()
    if fmt == "png":
        assert data.startswith(b"\x89PNG\r\n\x1a\n") and len(data) > 10_000
    elif fmt == "pdf":
        assert data.startswith(b"%PDF") and b"%%EOF" in data[-32:]
    else:
        assert b"<svg" in data[:2000] and data.rstrip().endswith(b"</svg>")


@pytest.mark.parametrize("fmt", ["png", "svg", "pdf"])
def test_figures_render(tmp_path, fmt):
    _check_file(plot_cradle(tmp_path / f"c.{fmt}"), fmt)
    plot_sectors(path=tmp_path / f"s.{fmt}")
    _check_file(tmp_path / f"s.{fmt}", fmt)


def test_figure_errors(tmp_path, monkeypatch):
    with pytest.raises(iq.InputError, match="must end in one of"):
        plot_sectors(path=tmp_path / "x.jpg")
    with pytest.raises(iq.InputError, match="S = {u⁻}"):
        plot_admissible(iq.newtons_cradle(4, v=-1.0), tmp_path / "x.png")
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    with pytest.raises(iq.errors.OptionalDependencyError, match=r"pip install 'impactqp\[plot\]'"):
        plot_cradle(tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()


def test_committed_figures_are_small():
    root = Path(__file__).resolve().parent.parent / "docs" / "figures"
    for name in ("cradle.png", "sectors.png"):
        data = (root / name).read_bytes()
        assert data.startswith(b"\x89PNG") and len(data) < 200_000


def test_sector_axes_name_their_metric():
    from matplotlib.figure import Figure

    from impactqp.figures.plots import draw_sectors

    ax = Figure().add_subplot()
    draw_sectors(sector_picture(), ax)
    assert "G⁻¹-orthonormal" in ax.get_xlabel() and "G⁻¹-orthonormal" in ax.get_ylabel()
    assert "60°" in ax.get_title()


def _candidate_marks(ax, labels):
    legend = {h.get_label(): h for h in ax.get_legend().legend_handles}
    marks = [next(v for k, v in legend.items() if k.startswith(label)) for label in labels]
    return legend, marks


def test_every_candidate_has_its_own_marker_and_names_its_angle():
    from matplotlib.colors import to_rgba
    from matplotlib.figure import Figure

    p = iq.newtons_cradle(3)
    # two candidates at 0° and 30°, the first on Moreau's ε = 1 mark
    cands = {"moreau": iq.moreau(p, eps=1.0).u_plus, "file": [0.0, 0.0, 1.0],
             "again": [0.0, 0.0, 1.0]}
    pic = plane_picture(p, cands)
    ax = Figure().add_subplot()
    draw_plane(pic, ax)
    legend, marks = _candidate_marks(ax, list(cands))
    assert len(legend) == 5 + len(cands)
    styles = {(m.get_marker(), to_rgba(m.get_color())) for m in marks}
    assert len(styles) == len(cands)  # no two share a look
    assert all(m.get_marker() not in ("o", "s", "None", None) for m in marks)  # not ε, not u⁻
    labels = [m.get_label() for m in marks]
    assert "α = 0.0°" in labels[0] and "α = 30.0°" in labels[1] and "α = 30.0°" in labels[2]
    # the α values are in the legend, not written over the picture
    assert not any("α" in t.get_text() for t in ax.texts)
    # a candidate drawn over another leaves the one below visible: only the first is filled
    assert [m.get_markerfacecolor() == "none" for m in marks] == [False, True, True]
    # the arcs of equal angles lie on circles of their own
    radii = [np.linalg.norm(c.arc[0] - pic.u_minus) for c in pic.candidates]
    assert len({round(r, 9) for r in radii}) == len(cands)


def test_the_legend_lies_outside_the_picture(tmp_path):
    from matplotlib.figure import Figure

    ax = Figure().add_subplot()
    draw_plane(plane_picture(iq.newtons_cradle(3), {"sector": [0.0, 0.0, 1.0]}), ax)
    ax.figure.canvas.draw()
    box = ax.get_legend().get_window_extent()
    assert box.y1 <= ax.get_window_extent().y0  # below the axes, over nothing drawn


def test_candidate_styles_are_distinct():
    from impactqp.figures.plots import candidate_style

    looks = {(s["marker"], s["color"]) for s in map(candidate_style, range(42))}
    assert len(looks) == 42


def test_plot_S_of_a_file_with_two_candidates(tmp_path, capsys):
    from impactqp.cli.main import main

    out = tmp_path / "S.png"
    root = Path(__file__).resolve().parent.parent
    assert main(["plot", "S", str(root / "examples" / "cradle.toml"), "--out", str(out)]) == 0
    _check_file(out, "png")


def test_benchmark_plot_has_one_legend_per_kind_and_one_colour_per_solver():
    from matplotlib.colors import to_rgba

    from benchmarks import report

    root = Path(__file__).resolve().parent.parent
    rows = report.read_rows(root / "benchmarks" / "reference" / "results.csv")
    fig = report.plot_figure(rows)
    try:
        legends = [leg for ax in fig.axes if (leg := ax.get_legend()) is not None]
        titles = [leg.get_title().get_text() for leg in legends]
        assert titles == [title for title, _ in report.PANELS]
        entries = [[t.get_text() for t in leg.get_texts()] for leg in legends]
        plotted = {r["method"] for r in rows if report._panel(r["method"], r["group"])
                   is not None and r["median_s"] is not None
                   and r["family"] in report.SIZE_LABEL
                   and r["family"] not in report.RUN_FAMILIES}
        assert sorted(sum(entries, [])) == sorted(plotted | {"iq:auto (for comparison)"})
        assert max(map(len, entries)) <= 12  # no legend of 27 series
        own, via, raw = entries
        assert all(m.startswith("iq:") for m in own + via)
        assert all(not m.startswith("iq:") or "comparison" in m for m in raw)
        # a solver keeps its colour from column to column
        colour = {t.get_text(): to_rgba(h.get_color())
                  for leg in legends for t, h in zip(leg.get_texts(), leg.legend_handles)}
        assert colour["iq:clarabel"] == colour["raw:clarabel"]
        assert colour["iq:qpsolvers:daqp"] == colour["raw:qpsolvers:daqp"]
        for names in entries:  # within a column, no two methods look alike
            looks = {(colour[n], h.get_marker(), h.get_linestyle()) for n, h in
                     zip(names, next(leg for leg in legends if leg.get_texts()[0].get_text()
                                     == names[0]).legend_handles)}
            assert len(looks) == len(names)
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)
