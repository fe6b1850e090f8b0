"""Frictional impacts through problem files and the command line: the schema's contact_dim
and law "coulomb" (mu, e) round-trip exactly and are read strictly; ``impactqp solve``,
``verify`` and ``fclib`` print figures that agree with the library and the closed form."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
import impactqp.cli as cli
from impactqp.base.arrays import as_dense
from impactqp.laws.catalogue import law_named

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "examples" / "sphere_on_plane.toml"
FCLIB = ROOT / "tests" / "data" / "fclib" / "LMGC_GlobalFrictionContactProblem00046.hdf5"
STICK = np.array([5 / 7, 1.0, -50 / 7])
"""u⁺ of the sample: the sphere (1 kg, R = 0.1 m) at (1, −2, 0) with e = 0.5, μ = 0.3 sticks."""


def slip(mu: float) -> np.ndarray:
    """u⁺ of the sample's sphere when it slides (μ < 2/21): P_n = 3, P_t = −3μ."""
    tangent = -3.0 * mu
    return np.array([1.0 + tangent, 1.0, 0.1 * tangent / 0.004])


def two_contacts() -> iq.ImpactProblem:
    """A disk landing on two collinear supports (two planar frictional contacts)."""
    sphere = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.3])
    return iq.ImpactProblem(sphere.M, np.hstack([as_dense(sphere.W)] * 2), sphere.u_minus,
                            contact_dim=2)


CASES = {
    "planar": (lambda: iq.friction.sphere_on_plane(2.0, 0.1, [1.0, -2.0, 0.5]), (0.3, 0.5)),
    "spatial": (lambda: iq.friction.two_spheres([1.0, 3.0], [0.1, 0.2], [1, 0.2, 0, 0, 0, 1,
                                                                -1, 0, 0.3, 0, 0.5, 0]),
                (1 / 3, None)),
    "per contact": (two_contacts, (np.array([0.2, 0.7]), np.array([0.0, 1 / 3]))),
}


# --- files ------------------------------------------------------------------------------------
@pytest.mark.parametrize("suffix", [".toml", ".json"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_frictional_problems_round_trip_exactly(tmp_path, suffix, case):
    build, coefficients = CASES[case]
    p = build()
    u_plus = p.u_minus * 0.1 + 1e-17
    path = iq.save_problem(p, tmp_path / f"p{suffix}", law="coulomb",
                           coefficients=coefficients, u_plus=u_plus)
    back = iq.load_problem(path)
    q = back.problem
    assert q.contact_dim == p.contact_dim > 1 and back.law == "coulomb"
    assert np.array_equal(as_dense(q.M), as_dense(p.M))
    assert np.array_equal(as_dense(q.W), as_dense(p.W))
    assert np.array_equal(q.u_minus, p.u_minus) and np.array_equal(back.u_plus, u_plus)
    for given, read in zip(coefficients, back.coefficients, strict=True):
        assert (given is None and read is None) or np.array_equal(read, given)
    mine = iq.solve(p, law_named("coulomb", coefficients))
    theirs = iq.solve(q, law_named("coulomb", back.coefficients))
    assert np.array_equal(mine.u_plus, theirs.u_plus) and theirs.certificate.ok


def test_the_sample_file_is_the_builders_sphere_and_sticks():
    content = iq.load_problem(SAMPLE)
    p = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])
    assert content.law == "coulomb" and content.coefficients == (0.3, 0.5)
    np.testing.assert_allclose(as_dense(content.problem.M), as_dense(p.M), rtol=1e-15)
    assert np.array_equal(as_dense(content.problem.W), as_dense(p.W))
    result = iq.solve(content.problem, law_named("coulomb", content.coefficients))
    np.testing.assert_allclose(result.u_plus, STICK, atol=1e-12)
    S = content.problem.admissible_set(mu=0.3)
    assert S.contains(content.u_plus) and S.contains(result.u_plus)


GENERAL = '"M": [[1, 0, 0], [0, 1, 0], [0, 0, 0.004]], "W": [[0, 1], [1, 0], [0, 0.1]]'
SPHERE = '{' + GENERAL + ', "contact_dim": 2, "u_minus": [1, -2, 0]'

BAD = [
    (SPHERE.replace('"contact_dim": 2', '"contact_dim": true') + '}', "contact_dim must be"),
    (SPHERE.replace('"contact_dim": 2', '"contact_dim": 2.0') + '}', "contact_dim must be"),
    (SPHERE.replace('"contact_dim": 2', '"contact_dim": 4') + '}', "contact_dim must be"),
    (SPHERE.replace('"contact_dim": 2', '"contact_dim": "2"') + '}', "contact_dim must be"),
    (SPHERE.replace('[0, 1], [1, 0], [0, 0.1]', '[0, 1, 0], [1, 0, 1], [0, 0.1, 0]') + '}',
     "W has 3 columns, not a multiple of contact_dim = 2"),
    ('{"masses": [1, 1], "contact_dim": 2, "u_minus": [1, 0]}', "a chain's contacts"),
    ('{' + GENERAL + ', "u_minus": [1, -2, 0], "law": "coulomb", "mu": 0.3}',
     "law 'coulomb' needs frictional contacts"),
    (SPHERE + ', "law": "newton", "e": 0.5}', "law 'newton' acts on frictionless contacts"),
    (SPHERE + ', "law": "moreau"}', "law 'moreau' acts on frictionless contacts"),
    (SPHERE + ', "law": "coulomb", "mu": -0.1}', "mu must be ≥ 0"),
    (SPHERE + ', "law": "coulomb", "mu": [0.1, 0.2]}', "mu must be one number or one per "
                                                        "contact (1,)"),
    (SPHERE + ', "law": "coulomb", "mu": "0.3"}', "mu must be a number"),
    (SPHERE + ', "law": "coulomb", "mu": [true]}', "mu[0] must be a number"),
    (SPHERE + ', "law": "coulomb", "mu": [[0.3]]}', "mu[0] must be a number"),
    (SPHERE + ', "law": "coulomb", "mu": 1e999}', "mu must be finite"),
    (SPHERE + ', "law": "coulomb", "mu": 0.3, "e": 1.5}', "e must lie in [0, 1]"),
    (SPHERE + ', "law": "coulomb", "mu": 0.3, "e": -0.5}', "e must lie in [0, 1]"),
    (SPHERE + ', "law": "coulomb", "mu": 0.3, "e": [0.5, 0.5]}', "e must be a scalar or "
                                                                  "have shape (1,)"),
    (SPHERE + ', "law": "coulomb", "mu": 0.3, "e": false}', "e must be a number"),
    (SPHERE + ', "law": "coulomb", "mu": 0.3, "eps": 0.5}', "'eps' does not fit law 'coulomb'"),
    (SPHERE + ', "mu": 0.3}', "'mu' does not fit no law"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "law": "newton", "e": 0.5, "mu": 0.3}',
     "'mu' does not fit law 'newton'"),
    (SPHERE + ', "law": "coulomb", "mu": 0.3, "mu": 0.4}', "duplicate key 'mu'"),
    (SPHERE + ', "law": "coulomb", "friction": 0.3}', "unknown key(s) ['friction']"),
    (SPHERE + ', "law": "coulomb", "mu": 0.3, "u_plus": [1, 1]}', "u_plus must have shape (3,)"),
]


@pytest.mark.parametrize("text, message", BAD)
def test_bad_frictional_files_name_the_field(tmp_path, text, message):
    path = tmp_path / "bad.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(iq.errors.ProblemFileError) as info:
        iq.load_problem(path)
    assert message in str(info.value) and str(path) in str(info.value)


def test_non_finite_mu_in_toml(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(SAMPLE.read_text(encoding="utf-8").replace("mu = 0.3", "mu = nan"))
    with pytest.raises(iq.errors.ProblemFileError, match="mu must be finite"):
        iq.load_problem(path)


def test_saving_refuses_what_could_not_be_read_back(tmp_path):
    p = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])
    with pytest.raises(iq.InputError, match=r"pair \(mu, e\)"):
        iq.save_problem(p, tmp_path / "a.toml", law="coulomb", coefficients=0.3)
    with pytest.raises(iq.InputError, match="acts on frictionless contacts"):
        iq.save_problem(p, tmp_path / "b.toml", law="newton", coefficients=0.5)
    with pytest.raises(iq.InputError, match="mu must be ≥ 0"):
        iq.save_problem(p, tmp_path / "c.toml", law="coulomb", coefficients=(-1.0, 0.5))
    with pytest.raises(iq.InputError, match="needs frictional contacts"):
        iq.save_problem(iq.newtons_cradle(), tmp_path / "d.toml", law="coulomb",
                        coefficients=(0.3, 0.5))
    assert not list(tmp_path.iterdir())


def test_coulomb_by_name_takes_the_pair():
    assert law_named("coulomb", (0.3, None)).restitution == 0.0
    law = law_named("coulomb", (np.array([0.1, 0.2]), 0.5))
    assert np.array_equal(law.mu, [0.1, 0.2]) and law.restitution == 0.5
    with pytest.raises(iq.InputError, match=r"pair \(mu, e\)"):
        law_named("coulomb", 0.3)
    with pytest.raises(iq.InputError, match="needs its friction coefficient 'mu'"):
        law_named("coulomb", (None, 0.5))
    with pytest.raises(iq.errors.RestitutionError):
        law_named("coulomb", (0.3, 2.0))


# --- the command line -------------------------------------------------------------------------
def run(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def sample_json(tmp_path):
    content = iq.load_problem(SAMPLE)
    return iq.save_problem(content.problem, tmp_path / "sphere.json", law="coulomb",
                           coefficients=content.coefficients, u_plus=content.u_plus)


def test_solve_prints_the_law_and_its_certificate(capsys):
    code, out, _ = run(capsys, "solve", SAMPLE)
    assert code == 0
    assert "law coulomb, μ = (+0.3), e = (+0.5)" in out
    assert "u⁺         (+0.714286, +1, -7.14286)" in out
    assert "admissible (u⁺ ∈ S with friction): yes" in out
    assert "certificate: ok" in out and "natural_map" in out and "classification" not in out


@pytest.mark.parametrize("flags, expected", [
    ([], STICK),
    (["--mu", "0.05", "--e", "0.5"], slip(0.05)),
    (["--mu", "0"], np.array([1.0, 1.0, 0.0])),  # e from the file
    (["--mu", "0.3", "--backend", "nsgs"], STICK),
    (["--law", "coulomb", "--mu", "0.05", "--backend", "clarabel"], slip(0.05)),
])
def test_solve_json_agrees_with_the_library_and_the_closed_form(capsys, sample_json, flags,
                                                                 expected):
    code, out, _ = run(capsys, "solve", sample_json, "--json", *flags)
    assert code == 0
    report = json.loads(out)
    assert report["law"] == "coulomb" and report["classification"] is None
    np.testing.assert_allclose(report["u_plus"], expected, atol=1e-12)
    mu = float(flags[flags.index("--mu") + 1]) if "--mu" in flags else 0.3
    e = float(flags[flags.index("--e") + 1]) if "--e" in flags else 0.5  # else the file's
    library = iq.solve(iq.load_problem(sample_json).problem, iq.Coulomb(mu, e))
    np.testing.assert_allclose(report["u_plus"], library.u_plus, atol=1e-12)
    np.testing.assert_allclose(report["impulses"], library.impulses, atol=1e-12)
    cert = report["certificate"]
    assert cert["ok"] is True
    assert max(cert[k] for k in ("momentum", "natural_map", "cone", "non_penetration")) \
        <= cert["tolerance"]
    assert report["admissibility"]["admissible"] is True


def test_a_frictional_file_without_law_asks_for_mu(capsys, tmp_path):
    p = iq.load_problem(SAMPLE).problem
    path = iq.save_problem(p, tmp_path / "bare.toml")
    code, _, err = run(capsys, "solve", path)
    assert code == 2 and "law 'coulomb' needs its coefficients" in err and "--mu" in err
    code, out, _ = run(capsys, "solve", path, "--mu", "0.3", "--json")  # e = 0 by default
    np.testing.assert_allclose(json.loads(out)["u_plus"], [5 / 7, 0.0, -50 / 7], atol=1e-12)


@pytest.mark.parametrize("flags, message", [
    (["--law", "newton", "--e", "0.5"], "frictional contacts"),
    (["--law", "moreau"], "frictional contacts"),
    (["--eps", "0.5"], "--eps does not apply to law 'coulomb'"),
    (["--E", "1"], "--E does not apply to law 'coulomb'"),
    (["--mu", "-1"], "mu must be ≥ 0"),
    (["--mu", "0.1,0.2"], "mu must be one number or one per contact"),
    (["--mu", "x"], "--mu must be numbers"),
    (["--e", "2"], "restitution must lie in [0, 1]"),
    (["--backend", "osqp"], "'osqp' does not solve frictional contact problems"),
    (["--backend", "lemke"], "unknown backend 'lemke'"),
])
def test_solve_frictional_bad_input_exits_2(capsys, flags, message):
    code, out, err = run(capsys, "solve", SAMPLE, *flags)
    assert code == 2 and out == "" and message in err and len(err.splitlines()) == 1


def test_mu_does_not_apply_to_frictionless_files(capsys):
    code, _, err = run(capsys, "solve", ROOT / "examples" / "cradle.toml", "--mu", "0.3")
    assert code == 2 and "--mu does not apply to law 'moreau'" in err
    code, _, err = run(capsys, "verify", ROOT / "examples" / "cradle.toml", "--mu", "0.3")
    assert code == 2 and "--mu applies to frictional contacts" in err


def test_verify_checks_u_plus_against_s_with_friction(capsys, tmp_path):
    code, out, _ = run(capsys, "verify", SAMPLE)  # the frictionless rebound: Λ_t = 0
    assert code == 0 and "verdict: ADMISSIBLE" in out and "friction cones" in out
    stick = ",".join(repr(float(x)) for x in STICK)
    assert run(capsys, "verify", SAMPLE, "--u-plus", stick)[0] == 0
    code, out, _ = run(capsys, "verify", SAMPLE, "--u-plus", stick, "--mu", "0.01")
    assert code == 1 and "fails: kinetic" in out  # |Λ_t| = 2/7 > 0.01 · 3
    assert not iq.load_problem(SAMPLE).problem.admissible_set(mu=0.01).contains(STICK)
    code, out, _ = run(capsys, "verify", SAMPLE, "--u-plus", "1,2.5,0", "--json")
    report = json.loads(out)
    assert code == 1 and report["failed"] == ["energetic"]  # a gain of energy
    bare = iq.save_problem(iq.load_problem(SAMPLE).problem, tmp_path / "bare.json",
                           u_plus=STICK)
    code, _, err = run(capsys, "verify", bare)
    assert code == 2 and "depends on μ" in err
    assert run(capsys, "verify", bare, "--mu", "0.3")[0] == 0


def test_plot_s_refuses_frictional_contacts(capsys, tmp_path):
    """The picture of S is of frictionless contacts: a frictional file is refused by name, not
    drawn as if its tangent columns were contacts."""
    code, _, err = run(capsys, "plot", "S", SAMPLE, "--out", tmp_path / "S.png")
    assert code == 2 and "frictional (contact_dim = 2)" in err
    assert not list(tmp_path.iterdir())


def _library_figures(backend: str) -> tuple[str, dict]:
    found = iq.solve_friction(iq.load_fclib(FCLIB), backend=backend)
    return found.backend, {**found.certificate.values, **found.certificate.reported}


@pytest.mark.parametrize("backend", ["auto", "clarabel", "nsgs"])
def test_fclib_prints_the_certificate_of_solve_friction(capsys, backend):
    code, out, _ = run(capsys, "fclib", FCLIB, "--backend", backend, "--json")
    assert code == 0
    report = json.loads(out)
    method, figures = _library_figures(backend)
    assert report["method"] == method and report["contacts"] == 9
    assert report["contact_dim"] == 3 and report["solve_time"] > 0
    cert = report["certificate"]
    assert cert["ok"] is True and cert["tolerance"] == 1e-8
    for name, value in figures.items():
        assert cert[name] == pytest.approx(value, rel=1e-6, abs=1e-15), name
    assert max(cert["natural_map"], cert["cone"], cert["velocity"]) <= 1e-8


def test_fclib_text_figures_parse_back(capsys):
    code, out, _ = run(capsys, "fclib", FCLIB, "--tol", "1e-10")
    assert code == 0 and "9 contacts, d = 3" in out and "certificate: ok (tol 1e-10)" in out
    rows = {line.split()[0]: float(line.split()[-1]) for line in out.splitlines()[3:]}
    assert set(rows) == {"natural", "Siconos", "cone", "dual", "velocity", "penetration",
                         "complementarity"}
    assert rows["natural"] <= 1e-10 and rows["Siconos"] <= rows["natural"] * (1 + 1e-3)


def test_fclib_failures_exit_2(capsys, tmp_path):
    bad = tmp_path / "no_solution.hdf5"  # u_n = −1 whatever r: none
    iq.save_fclib(iq.FrictionContactProblem(np.array([[0.0, 0.0], [0.0, 1.0]]), [-1.0, 0.0],
                                            [0.5], contact_dim=2), bad)
    for argv, message in [([bad], "no method certified"),
                          ([tmp_path / "missing.hdf5"], "cannot read"),
                          ([SAMPLE], "not an HDF5 file"),
                          ([FCLIB, "--tol", "2"], "tol must be a tolerance"),
                          ([FCLIB, "--tol", "nan"], "tol")]:
        code, out, err = run(capsys, "fclib", *argv)
        assert code == 2 and out == "" and message in err, (argv, err)
        assert len(err.strip().splitlines()) == 1
    with pytest.raises(SystemExit) as info:
        cli.main(["fclib", str(FCLIB), "--backend", "osqp"])
    assert info.value.code == 2


def test_fclib_garbage_in_a_fresh_process(tmp_path):
    path = tmp_path / "garbage.hdf5"
    path.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(range(256)) * 4)
    done = subprocess.run([sys.executable, "-m", "impactqp", "fclib", str(path)],
                          capture_output=True, text=True, timeout=60, stdin=subprocess.DEVNULL)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("impactqp: error:")
