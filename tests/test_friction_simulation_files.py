"""Frictional simulations through simulation files and ``impactqp simulate``: a file's
``contact_dim`` and law ``coulomb`` (mu, e) give the same run as the builders and
:func:`impactqp.simulate`, agree with the closed forms of docs/theory.md §17, and every
wrong field is refused by name with the command line's exit status 2."""

from __future__ import annotations

import csv
import json
import re
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
import impactqp.cli as cli
from impactqp.base.arrays import as_dense
from impactqp.errors import ProblemFileError
from impactqp.io.simulation_files import read_simulation

ROOT = Path(__file__).resolve().parents[1]
SPHERE = ROOT / "examples" / "rolling_sphere.toml"
INCLINE = ROOT / "examples" / "block_on_incline.toml"
V0, MU, G, R = 2.0, 0.3, 9.81, 0.1
"""The rolling-sphere sample: initial speed, friction coefficient, gravity, radius."""
FAILED = 2
"""The command line's exit status for a refused file."""


def run_file(path: Path, **override) -> iq.Trajectory:
    system, law, sim = read_simulation(path)
    return iq.simulate(system, law, **{**sim, **override})


def assert_same_run(a: iq.Trajectory, b: iq.Trajectory) -> None:
    np.testing.assert_allclose(a.t, b.t, rtol=0, atol=1e-15)
    np.testing.assert_allclose(a.q, b.q, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(a.v, b.v, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(a.impulses, b.impulses, rtol=1e-10, atol=1e-12)
    assert a.certified and b.certified and len(a.events) == len(b.events)


# --- the samples against the builders ----------------------------------------------------
def test_the_sphere_file_is_the_builders_sphere():
    system, law, sim = read_simulation(SPHERE)
    built = iq.simulation.rolling_sphere(mass=1.0, radius=R, gravity=G, velocity=V0, gap=-1e-9)
    assert system.contact_dim == built.contact_dim == 2 and system.n_contacts == 1
    np.testing.assert_allclose(as_dense(system.M),
                               as_dense(built.M), rtol=1e-15)
    np.testing.assert_array_equal(system.H, built.H)
    np.testing.assert_array_equal(system.b, built.b)
    np.testing.assert_array_equal(system.q0, built.q0)
    np.testing.assert_array_equal(system.v0, built.v0)
    assert isinstance(law, iq.Coulomb) and law.coefficients == (MU, 0.0)
    assert sim == {"scheme": "moreau-jean", "t_end": 0.5, "h": 0.001}
    assert_same_run(iq.simulate(system, law, **sim),
                    iq.simulate(built, iq.Coulomb(MU, 0.0), 0.5, h=0.001))


def test_the_sphere_file_rolls_at_five_sevenths():
    """Sliding to rolling (docs/theory.md §17): the slip ẋ + Rφ̇ decreases at 7/2 μg until
    t* = 2v₀/(7μg), after which the sphere rolls at 5/7 v₀; Moreau–Jean within O(h)."""
    tr = run_file(SPHERE)
    h = 0.001
    slip = tr.v[:, 0] + R * tr.v[:, 2]
    t_star = 2 * V0 / (7 * MU * G)
    rolling = tr.t[np.argmax(np.abs(slip) < 1e-9)]
    assert abs(rolling - t_star) <= 2 * h
    assert abs(tr.v[-1, 0] - 5 / 7 * V0) <= 10 * h
    assert abs(tr.v[-1, 2] + 5 / 7 * V0 / R) <= 10 * h / R
    sliding = tr.t < t_star - 2 * h
    np.testing.assert_allclose(slip[sliding], V0 - 3.5 * MU * G * tr.t[sliding],
                               atol=10 * h)
    np.testing.assert_allclose(tr.v[:, 1], 0.0, atol=1e-9)  # it stays on the floor


def test_the_incline_file_is_the_builders_block_and_stops_where_the_closed_form_says():
    tr = run_file(INCLINE)
    alpha, mu, v0, h = np.pi / 6, 0.7, 3.0, 0.002
    built = iq.simulation.block_on_incline(alpha, mass=2.0, dim=2, speed=v0, gap=-1e-9)
    assert_same_run(tr, iq.simulate(built, iq.Coulomb(mu), 0.6, h=h))
    a = G * (np.sin(alpha) + mu * np.cos(alpha))  # deceleration up the slope
    up = np.array([np.cos(alpha), np.sin(alpha)])
    distance = tr.q[-1] @ up
    assert abs(distance - v0**2 / (2 * a)) <= 5 * v0 * h
    np.testing.assert_allclose(tr.v[-1], 0.0, atol=1e-9)  # μ > tan α: it stays
    stopped = tr.t[np.argmax(np.linalg.norm(tr.v, axis=1) < 1e-9)]
    assert abs(stopped - v0 / a) <= 2 * h


SPATIAL = {
    "version": 1,
    "system": {"kind": "linear", "contact_dim": 3, "M": [[2.0, 0, 0], [0, 2.0, 0], [0, 0, 2.0]],
               "q0": [0.0, 0.0, -1e-9], "v0": [1.0, 0.5, 0.0], "force": [0.0, 0.0, -19.62],
               "H": [[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]], "b": [0.0]},
    "law": {"name": "coulomb", "mu": [0.25], "e": 0.5},
    "simulation": {"t_end": 0.6, "h": 0.005, "theta": 1.0},
}
"""A 2 kg block on a level floor in space (contact_dim = 3), sliding at (1, 0.5) m/s."""


def test_a_spatial_linear_file_is_the_builders_block_in_space(tmp_path):
    path = tmp_path / "block.json"
    path.write_text(json.dumps(SPATIAL))
    tr = run_file(path)
    built = iq.simulation.block_on_incline(0.0, mass=2.0, dim=3, speed=1.0, gap=-1e-9)
    built = iq.LinearSystem(built.M, built.q0, [1.0, 0.5, 0.0], built.constant_force, built.H,
                            built.b, contact_dim=3)
    assert_same_run(tr, iq.simulate(built, iq.Coulomb([0.25], 0.5), 0.6, h=0.005, theta=1.0))
    speed, a = np.hypot(1.0, 0.5), 0.25 * G  # it slides straight, decelerating at μg
    assert abs(np.linalg.norm(tr.q[-1, :2]) - speed**2 / (2 * a)) <= 5 * speed * 0.005
    np.testing.assert_allclose(tr.q[-1, :2] / np.linalg.norm(tr.q[-1, :2]), [1.0, 0.5] / speed,
                               atol=1e-9)


# --- the command line --------------------------------------------------------------------
def test_the_cli_prints_the_librarys_numbers(tmp_path, capsys):
    tr = run_file(SPHERE)
    out = tmp_path / "run.csv"
    assert cli.main(["simulate", str(SPHERE), "--quiet", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "contact_dim=2" in text and "Coulomb(mu=0.3, restitution=0)" in text
    assert f"{tr.t.size} records, {len(tr.events)} impact problems" in text
    assert "certificates: all ok" in text and f"u⁺ ∈ S: {len(tr.events)} of" in text
    first, last, drift = map(float, re.search(r"energy: (\S+) → (\S+) \(largest relative "
                                              r"change (\S+)\)", text).groups())
    np.testing.assert_allclose([first, last], tr.total_energy[[0, -1]], rtol=1e-9)
    np.testing.assert_allclose(drift, tr.energy_drift(), rtol=1e-2)
    with out.open(encoding="utf-8") as handle:
        rows = list(csv.reader(handle))
    header = rows[0]
    assert header[7:9] == ["lambda0_n", "lambda0_t1"]
    table = np.array(rows[1:], dtype=float)
    np.testing.assert_allclose(table[:, 7:9], tr.impulses, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(table[:, 4:7], tr.v, rtol=1e-12, atol=1e-15)
    assert (tmp_path / "run.events.csv").is_file()


def test_the_cli_json_report_and_its_overrides(tmp_path, capsys):
    tr = run_file(SPHERE, t_end=0.3, h=0.002)
    out = tmp_path / "run.npz"
    assert cli.main(["simulate", str(SPHERE), "--json", "--quiet", "--t-end", "0.3", "--h",
                     "0.002", "--out", str(out)]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["scheme"] == "moreau-jean" and report["certified"]
    assert report["records"] == tr.t.size == 151 and report["events"] == len(tr.events)
    assert report["admissible"] == int(tr.admissible().sum())
    np.testing.assert_allclose(report["final_state"]["v"], tr.v[-1], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(report["final_state"]["q"], tr.q[-1], rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(report["energy"]["final"], tr.total_energy[-1], rtol=1e-12)
    assert abs(report["final_state"]["v"][0] - 5 / 7 * V0) <= 10 * 0.002
    saved = np.load(out)
    assert saved["impulses"].shape == (151, 2)  # the normal and the tangent of the contact
    np.testing.assert_allclose(saved["impulses"], tr.impulses, rtol=1e-12, atol=1e-15)


def test_the_cli_refuses_event_driven_friction_by_its_option(capsys):
    assert cli.main(["simulate", str(SPHERE), "--quiet", "--scheme", "event-driven"]) == FAILED
    err = capsys.readouterr().err
    assert "--scheme = 'event-driven' has no friction" in err and "moreau-jean" in err


# --- refusals ----------------------------------------------------------------------------
TWO_COLUMNS = "H = [[0.0, 1.0],\n     [1.0, 0.0],\n     [0.0, 0.1]]"
REFUSALS = {
    "contact_dim 4": ([("contact_dim = 2 ", "contact_dim = 4 ")],
                      "system.contact_dim must be one of the integers (1, 2, 3), got 4"),
    "contact_dim bool": ([("contact_dim = 2 ", "contact_dim = true ")],
                         "system.contact_dim must be one of the integers"),
    "contact_dim float": ([("contact_dim = 2 ", "contact_dim = 2.0 ")],
                          "system.contact_dim must be one of the integers"),
    "H columns": ([(TWO_COLUMNS, "H = [[0.0, 1.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.1, 0.1]]")],
                  "system.H has 3 columns, not a multiple of system.contact_dim = 2"),
    "b per column": ([("b = [-0.1]", "b = [-0.1, 0.0]")], "b must have shape (1,)"),
    "coulomb frictionless": ([("contact_dim = 2 ", "contact_dim = 1 "),
                              ("b = [-0.1]", "b = [-0.1, 0.0]")],
                             "law 'coulomb' needs frictional contacts"),
    "newton frictional": ([('name = "coulomb"\nmu = 0.3\ne = 0.0', 'name = "newton"\ne = 0.0')],
                          "law 'newton' acts on frictionless contacts, but contact_dim = 2"),
    "event-driven": ([('scheme = "moreau-jean"', 'scheme = "event-driven"')],
                     "simulation.scheme = 'event-driven' has no friction"),
    "mu missing": ([("mu = 0.3\n", "")], "law 'coulomb' needs its coefficient 'mu'"),
    "mu negative": ([("mu = 0.3", "mu = -0.3")], "mu must be ≥ 0"),
    "mu bool": ([("mu = 0.3", "mu = true")], "law.mu must be a number or an array of numbers"),
    "mu string": ([("mu = 0.3", 'mu = "0.3"')], "law.mu must be a number"),
    "mu per contact": ([("mu = 0.3", "mu = [0.3, 0.2]")], "mu must be one number or one per "
                       "contact (1,)"),
    "mu nan": ([("mu = 0.3", "mu = nan")], "law.mu must be finite"),
    "e above 1": ([("e = 0.0", "e = 1.5")], "e must lie in [0, 1]"),
    "e per contact": ([("e = 0.0", "e = [0.5, 0.5]")], "e must be a scalar or have shape (1,)"),
    "eps with coulomb": ([("e = 0.0", "eps = 0.5")], "coefficient 'eps' does not fit law "
                         "'coulomb'"),
    "unknown key": ([("mu = 0.3", "mu = 0.3\nnu = 0.1")], "unknown key(s) ['nu'] in [law]"),
}


@pytest.mark.parametrize("case", sorted(REFUSALS))
def test_every_wrong_field_is_refused_by_name(case, tmp_path, capsys):
    edits, message = REFUSALS[case]
    text = SPHERE.read_text(encoding="utf-8")
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new)
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ProblemFileError, match=re.escape(message)):
        read_simulation(path)
    assert cli.main(["simulate", str(path), "--quiet"]) == FAILED
    assert message in capsys.readouterr().err


@pytest.mark.parametrize(("kind", "extra", "law", "message"), [
    ("rolling_sphere", {}, {"name": "newton", "e": 0.5}, "law 'newton' acts on frictionless"),
    ("box_on_floor", {"dim": 4}, {"name": "coulomb", "mu": 0.3},
     "system.dim must be one of the integers (2, 3), got 4"),
    ("block_on_incline", {"angle": 2.0}, {"name": "coulomb", "mu": 0.3}, "angle must lie"),
    ("bouncing_ball", {}, {"name": "coulomb", "mu": 0.3}, "law 'coulomb' needs frictional"),
])
def test_the_builders_in_files_are_refused_by_name(kind, extra, law, message, tmp_path):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"system": {"kind": kind, **extra}, "law": law,
                                "simulation": {"t_end": 0.1}}))
    with pytest.raises(ProblemFileError, match=re.escape(message)):
        read_simulation(path)


def test_the_frictional_builders_run_from_files(tmp_path, capsys):
    """box_on_floor in space (four corners, contact_dim = 3) slides flat at μg until it
    stops (docs/theory.md §17) and saves three impulse components per corner."""
    path = tmp_path / "box.json"
    path.write_text(json.dumps({
        "system": {"kind": "box_on_floor", "dim": 3, "velocity": [1.0, 0.0], "gap": -1e-9},
        "law": {"name": "coulomb", "mu": 0.5}, "simulation": {"t_end": 0.3, "h": 0.005}}))
    tr = run_file(path)
    built = iq.simulation.box_on_floor(3, velocity=[1.0, 0.0], gap=-1e-9)
    assert_same_run(tr, iq.simulate(built, iq.Coulomb(0.5), 0.3, h=0.005))
    assert abs(tr.q[-1, 0] - 1.0 / (2 * 0.5 * G)) <= 5 * 0.005
    out = tmp_path / "box.csv"
    assert cli.main(["simulate", str(path), "--quiet", "--out", str(out)]) == 0
    header = out.read_text(encoding="utf-8").splitlines()[0].split(",")
    assert [h for h in header if h.startswith("lambda")] == [
        f"lambda{j}_{part}" for j in range(4) for part in ("n", "t1", "t2")]
    assert "certificates: all ok" in capsys.readouterr().out
