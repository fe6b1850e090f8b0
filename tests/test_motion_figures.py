"""Figures of any simulated system, checked by their data: coordinates grouped by kind on axes
of their own with names and units from the system, 1-based labels and dofs, velocities,
energies, impulses and contact states, and animations of the builders' bodies (or a refusal
by name)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
from impactqp.errors import ProblemFileError, UndrawableSystemError
from impactqp.simulation import (
    Coordinate,
    block_on_incline,
    box_on_floor,
    cradle_system,
    rolling_sphere,
)
from impactqp.simulation.contact_states import contact_states
from impactqp.simulation.pictures import frames_of
from impactqp.simulation.scenes import draw_scene

pytest.importorskip("matplotlib")
pytestmark = pytest.mark.filterwarnings("error")  # no warning escapes a figure

MU, V0, G = 0.3, 2.0, 9.81


@pytest.fixture(scope="module")
def sphere():
    """A sphere thrown sliding without spin: it slides, then rolls from 2v₀/(7μg)."""
    return iq.simulate(rolling_sphere(velocity=V0, gap=-1e-9), iq.Coulomb(MU, 0.0), 0.5,
                       h=0.001)


@pytest.fixture(scope="module")
def cradle():
    return iq.simulate(cradle_system(3), iq.SectorLaw(), 1.0, scheme="event-driven", h=0.05)


def test_coordinates_are_grouped_by_kind_with_units(sphere):
    axes = sphere.plot("positions").axes
    assert len(axes) == 2
    assert [ax.get_ylabel() for ax in axes] == ["position (m)", "angle (rad)"]
    assert [[line.get_label() for line in ax.get_lines()] for ax in axes] == [["x", "y"], ["φ"]]
    assert axes[-1].get_xlabel() == "t (s)"
    np.testing.assert_array_equal(axes[1].get_lines()[0].get_ydata(), sphere.q[:, 2])
    # φ reaches several radians but no longer flattens the metres: each kind has its scale
    assert sphere.q[:, 2].min() < -3
    low, high = axes[0].get_ylim()
    assert low > -0.5 and high < 1.5
    assert axes[1].get_ylim()[0] <= sphere.q[:, 2].min()
    velocities = sphere.plot("velocities")
    assert [ax.get_ylabel() for ax in velocities.axes] == ["velocity (m/s)",
                                                           "angular velocity (rad/s)"]
    assert velocities.axes[0].get_lines()[0].get_label() == "dx/dt"
    np.testing.assert_array_equal(velocities.axes[1].get_lines()[0].get_ydata(), sphere.v[:, 2])


def test_dofs_are_names_or_the_1_based_numbers_of_the_labels(sphere):
    by_name = sphere.plot(dofs=["φ"])
    by_number = sphere.plot(dofs=3)
    for fig in (by_name, by_number):
        (ax,) = fig.axes
        (line,) = ax.get_lines()
        assert line.get_label() == "φ" and ax.get_ylabel() == "angle (rad)"
        np.testing.assert_array_equal(line.get_ydata(), sphere.q[:, 2])
    with pytest.raises(iq.InputError, match="1-based"):
        sphere.plot(dofs=[0])
    with pytest.raises(iq.InputError, match="dofs"):
        sphere.plot(dofs=["z"])
    with pytest.raises(iq.InputError, match="dofs"):
        sphere.plot("energy", dofs=[1])


def test_a_system_from_matrices_has_coordinates_q1_to_qn():
    system = iq.LinearSystem(np.eye(2), [0.0, 0.5], [1.0, 0.0], [0.0, 0.0], [[-1.0], [1.0]],
                             [0.1])
    assert [c.name for c in system.coordinates] == ["q1", "q2"]
    tr = iq.simulate(system, iq.Moreau(eps=0.5), 0.5, h=0.01)
    (ax,) = tr.plot().axes
    assert [line.get_label() for line in ax.get_lines()] == ["q1", "q2"]
    assert ax.get_ylabel() == "coordinate" and ax.get_xlabel() == "t"  # units unknown
    np.testing.assert_array_equal(tr.plot(dofs=["q2"]).axes[0].get_lines()[0].get_ydata(),
                                  tr.q[:, 1])
    named = iq.LinearSystem(np.eye(2), [0.0, 0.0], [0.0, 0.0],
                            coordinates=[Coordinate("s", "translation"), ("θ", "rotation")])
    assert [(c.name, c.unit) for c in named.coordinates] == [("s", "m"), ("θ", "rad")]
    with pytest.raises(iq.errors.ShapeError, match="all n = 2"):
        iq.LinearSystem(np.eye(2), [0.0, 0.0], [0.0, 0.0], coordinates=["a"])
    with pytest.raises(iq.InputError, match="distinct"):
        iq.LinearSystem(np.eye(2), [0.0, 0.0], [0.0, 0.0], coordinates=["a", "a"])
    with pytest.raises(iq.InputError, match="kind must be one of"):
        Coordinate("a", "length")


def test_builders_name_their_coordinates():
    names = {
        "bouncing_ball": iq.simulation.bouncing_ball(),
        "cradle": cradle_system(3),
        "incline": block_on_incline(0.3),
        "sphere": rolling_sphere(),
        "box3": box_on_floor(3, velocity=[0.0, 0.0]),
    }
    got = {k: [(c.name, c.unit) for c in s.coordinates] for k, s in names.items()}
    assert got["bouncing_ball"] == [("y", "m")]
    assert got["cradle"] == [("x1", "m"), ("x2", "m"), ("x3", "m")]
    assert got["incline"] == [("x", "m"), ("y", "m")]
    assert got["sphere"] == [("x", "m"), ("y", "m"), ("φ", "rad")]
    assert [u for _, u in got["box3"]] == ["m"] * 3 + ["rad"] * 3


def test_energy_and_impulses(sphere):
    (ax,) = sphere.plot("energy").axes
    assert ax.get_ylabel() == "energy (J)" and len(ax.get_lines()) == 3
    np.testing.assert_allclose(ax.get_lines()[2].get_ydata(), sphere.total_energy)
    normal, tangent = sphere.plot("impulses").axes
    assert normal.get_ylabel() == "normal impulse (N·s)"
    assert tangent.get_ylabel() == "tangential impulse (N·s)"
    np.testing.assert_array_equal(normal.get_lines()[0].get_ydata(), sphere.impulses[:, 0])
    np.testing.assert_array_equal(tangent.get_lines()[0].get_ydata(), sphere.impulses[:, 1])


def test_contact_states_slide_then_stick(sphere):
    codes, names = contact_states(sphere)
    assert names == ("open", "stick", "slide") and codes.shape == (sphere.t.size, 1)
    # the closed form (docs/theory.md §17): sliding ends at 2v₀/(7μg)
    first_stick = sphere.t[np.argmax(codes[:, 0] == 1)]
    assert abs(first_stick - 2 * V0 / (7 * MU * G)) <= 2 * sphere.settings["h"]
    assert set(codes[1:, 0]) == {1, 2}  # closed throughout, no open record after the start
    # independently: the slip of the lowest point ẋ + Rφ̇ from the velocities
    slip = np.abs(sphere.v[:, 0] + 0.1 * sphere.v[:, 2])
    closed = codes[:, 0] > 0
    assert np.all(slip[closed & (codes[:, 0] == 1)] < 1e-6 * V0)
    assert np.all(slip[codes[:, 0] == 2] > 1e-6 * V0)
    (ax,) = sphere.plot("contacts").axes
    bars = {c.get_label(): c for c in ax.collections}
    assert set(bars) == {"open", "stick", "slide"}
    opened = bars["open"].get_paths()[0].vertices  # the first record only: no impulse yet
    assert (opened[:, 0].min(), opened[:, 0].max()) == pytest.approx(tuple(sphere.t[:2]))
    stick = bars["stick"].get_paths()[0].vertices
    assert stick[:, 0].min() == pytest.approx(first_stick)
    assert stick[:, 0].max() == pytest.approx(sphere.t[-1])
    assert [t.get_text() for t in ax.get_yticklabels()] == ["contact 1"]


def test_frictionless_contacts_are_open_or_closed(cradle):
    codes, names = contact_states(cradle)
    assert names == ("open", "closed") and codes.shape == (cradle.t.size, 2)
    closed = np.flatnonzero(codes.any(axis=1))
    assert closed.size and np.all(np.isin(cradle.t[closed], cradle.impact_times))


def test_animations_draw_the_builders_bodies(sphere, cradle):
    from matplotlib.figure import Figure

    _, Q = frames_of(sphere, 5)
    ax = Figure().add_subplot()
    update = draw_scene(sphere, ax, Q)
    ball, mark = update(Q[3])
    x, y, phi = Q[3]
    assert ball.center == pytest.approx((x, y)) and ball.radius == pytest.approx(0.1)
    (cx, tip_x), (cy, tip_y) = mark.get_data()
    np.testing.assert_allclose([tip_x - cx, tip_y - cy], 0.1 * np.array([-np.sin(phi),
                                                                         np.cos(phi)]))
    _, Q = frames_of(cradle, 4)
    ax = Figure().add_subplot()
    moved = draw_scene(cradle, ax, Q)(Q[2])
    balls = moved[3:]
    centres = np.array([b.center for b in balls])
    np.testing.assert_allclose(np.diff(centres[:, 0]), np.diff(Q[2]) + 2 * balls[0].radius)
    box = iq.simulate(box_on_floor(2, velocity=1.0, gap=-1e-9), iq.Coulomb(0.3, 0.0), 0.3,
                      h=0.001)
    _, Q = frames_of(box, 3)
    (patch,) = draw_scene(box, Figure().add_subplot(), Q)(Q[1])
    corners = patch.get_xy()[:4]
    np.testing.assert_allclose(corners.mean(axis=0), Q[1][:2], atol=1e-12)
    np.testing.assert_allclose(np.ptp(corners[:, 0]), 1.0, atol=1e-6)  # half size 0.5
    block = iq.simulate(block_on_incline(0.4, speed=1.0, gap=-1e-9), iq.Coulomb(0.2, 0.0),
                        0.2, h=0.001)
    _, Q = frames_of(block, 3)
    (patch,) = draw_scene(block, Figure().add_subplot(), Q)(Q[1])
    normal = np.array([-np.sin(0.4), np.cos(0.4)])
    heights = patch.get_xy()[:4] @ normal  # above the incline nᵀx = 0, two corners on it
    assert sorted(heights)[:2] == pytest.approx([Q[1] @ normal] * 2, abs=1e-9)


def test_balls_on_a_vertical_line_sit_on_the_ground():
    from matplotlib.figure import Figure

    for radius in (0.0, 0.1):  # q the lowest point of a point ball, else the centre
        tr = iq.simulate(iq.simulation.bouncing_ball(q0=1.0, radius=radius), iq.Newton(0.5),
                         1.0, scheme="event-driven", h=0.01)
        _, Q = frames_of(tr, 50)
        (ball,) = draw_scene(tr, Figure().add_subplot(), Q)(Q[np.argmin(Q[:, 0])])
        assert ball.center[1] - ball.radius == pytest.approx(Q[:, 0].min() - radius, abs=1e-9)
        assert ball.center[1] - ball.radius >= -1e-9


def test_an_animation_is_written_and_an_unknown_system_refused(tmp_path, sphere):
    movie = sphere.animate(tmp_path / "sphere.gif", frames=4, fps=4)
    assert (tmp_path / "sphere.gif").read_bytes()[:6] == b"GIF89a"
    assert movie is not None
    system = iq.LinearSystem(np.eye(2), [0.0, 0.5], [1.0, 0.0], [0.0, 0.0], [[-1.0], [1.0]],
                             [0.1])
    tr = iq.simulate(system, iq.Moreau(eps=0.5), 0.2, h=0.01)
    with pytest.raises(UndrawableSystemError, match="cannot animate") as err:
        tr.animate(tmp_path / "x.gif")
    assert "cradle_system" in str(err.value) and "rolling_sphere" in str(err.value)
    assert isinstance(err.value, iq.InputError)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sphere.gif"]


def test_simulation_files_name_coordinates(tmp_path):
    from impactqp.io.simulation_files import read_simulation

    root = Path(__file__).resolve().parent.parent
    system, _, _ = read_simulation(root / "examples" / "rolling_sphere.toml")
    assert [(c.name, c.kind) for c in system.coordinates] == [
        ("x", "translation"), ("y", "translation"), ("φ", "rotation")]
    text = (root / "examples" / "rolling_sphere.toml").read_text(encoding="utf-8")
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace('"rotation"]', '"spin"]'), encoding="utf-8")
    with pytest.raises(iq.InputError, match="kind must be one of"):
        read_simulation(bad)
    bad.write_text(text.replace('coordinates = ["x", "y", "φ"]', "coordinates = [1, 2, 3]"),
                   encoding="utf-8")
    with pytest.raises(ProblemFileError, match="list of strings"):
        read_simulation(bad)
