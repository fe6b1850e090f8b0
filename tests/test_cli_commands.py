import io
import json
import subprocess
import sys
import time

import numpy as np
import pytest

import impactqp as iq
import impactqp.cli as cli
from impactqp.cli.commands.solve import parse_numbers
from impactqp.cli.progress import progress


@pytest.fixture
def cradle_file(tmp_path):
    return iq.save_problem(iq.newtons_cradle(), tmp_path / "cradle.toml", law="moreau",
                           coefficients=1.0, u_plus=[0.0, 0.0, 1.0])


@pytest.fixture
def dense_file(tmp_path):
    return iq.save_problem(iq.random_impact(3, 2, seed=3), tmp_path / "dense.json", law="newton",
                           coefficients=[0.9, 0.2])


def run(capsys, *argv):
    code = cli.main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_solve_text_uses_the_file_law(capsys, cradle_file):
    code, out, _ = run(capsys, "solve", cradle_file)
    assert code == 0
    assert "law moreau, ε = 1" in out and "(-0.333333, +0.666667, +0.666667)" in out
    assert "admissible (u⁺ ∈ S): yes" in out and "certificate: ok" in out


@pytest.mark.parametrize("flags, law, u_plus", [
    ([], "moreau", [-1 / 3, 2 / 3, 2 / 3]),
    (["--eps", "0"], "moreau", [1 / 3, 1 / 3, 1 / 3]),
    (["--law", "sector"], "sector", [0.0, 0.0, 1.0]),
    (["--law", "newton", "--e", "0"], "newton", [1 / 3, 1 / 3, 1 / 3]),
    (["--law", "fremond", "--E", "1,0;0,1"], "fremond", [-1 / 3, 2 / 3, 2 / 3]),
])
def test_solve_json_flags_override_the_file(capsys, cradle_file, flags, law, u_plus):
    code, out, _ = run(capsys, "solve", cradle_file, "--json", *flags)
    assert code == 0
    report = json.loads(out)
    assert report["law"] == law
    np.testing.assert_allclose(report["u_plus"], u_plus, atol=1e-9)
    assert report["admissibility"]["admissible"] is True
    assert report["energy"]["before"] == pytest.approx(0.5)
    if law == "sector":
        assert report["classification"]["alpha_deg"] == pytest.approx(30.0)
        np.testing.assert_allclose(report["impulses"], [1.0, 1.0], atol=1e-9)


def test_solve_reports_inadmissible_newton(capsys, tmp_path):
    # local Newton is not guaranteed to stay in S (docs/theory.md §3): here kinetic energy grows
    # from 1 to 4/3
    p = iq.chain([1.0, 1.0, 1.0], [1.0, -1.0, 0.0])
    path = iq.save_problem(p, tmp_path / "n.json", law="newton", coefficients=[1.0, 0.0])
    code, out, _ = run(capsys, "solve", path, "--json")
    report = json.loads(out)
    assert code == 0 and report["admissibility"]["admissible"] is False
    assert report["admissibility"]["failed"] == ["energetic"]
    assert report["energy"]["after"] == pytest.approx(4 / 3)
    assert "admissible (u⁺ ∈ S): NO" in run(capsys, "solve", path)[1]


def test_no_impact_gives_null_angle(capsys, tmp_path):
    path = iq.save_problem(iq.chain([1.0, 1.0], [0.0, 1.0]), tmp_path / "sep.json")
    report = json.loads(run(capsys, "solve", path, "--json")[1])
    assert report["classification"]["alpha_deg"] is None
    assert "α = nan°" in run(capsys, "solve", path)[1]


@pytest.mark.parametrize("flags, message", [
    (["--eps", "0.5", "--law", "newton"], "--eps does not apply to law 'newton'"),
    (["--law", "fremond"], "law 'fremond' needs its coefficients"),
    (["--eps", "1.5"], "eps must lie in [0, 1]"),
    (["--eps", "x"], "--eps must be numbers"),
    (["--law", "fremond", "--E", "1,0;0"], "--E is ragged"),
    (["--backend", "nope"], "unknown backend"),
])
def test_solve_bad_input_exits_2(capsys, cradle_file, flags, message):
    code, _, err = run(capsys, "solve", cradle_file, *flags)
    assert code == 2 and message in err


def test_solve_bad_file_exits_2(capsys, tmp_path):
    path = tmp_path / "bad.json"
    path.write_text('{"masses": [1, 1], "u_minus": [1, 0], "speed": 3}')
    code, out, err = run(capsys, "solve", path)
    assert code == 2 and out == "" and "unknown key(s) ['speed']" in err and str(path) in err


def test_sector_law_needs_equal_balls(capsys, dense_file, tmp_path):
    code, _, err = run(capsys, "solve", dense_file, "--law", "sector")
    assert code == 2 and "1-D chains of balls" in err
    with pytest.raises(iq.InputError, match="walls are not supported"):
        iq.sector_law(iq.chain([1.0, 1.0], [1.0, 0.0], right_wall=True))
    r = iq.sector_law(iq.chain([2.0] * 5, [3.0, -1.0, 2.0, 0.0, 5.0]))
    np.testing.assert_array_equal(r.u_plus, [-1.0, 0.0, 2.0, 3.0, 5.0])
    assert r.certificate.ok and r.admissible


def test_verify_exit_codes(capsys, cradle_file, dense_file):
    code, out, _ = run(capsys, "verify", cradle_file)
    assert code == 0 and "verdict: ADMISSIBLE" in out and "in S" in out
    code, out, _ = run(capsys, "verify", cradle_file, "--u-plus", "0,0,1.01")
    assert code == 1 and "NOT ADMISSIBLE (fails: kinetic, energetic)" in out
    code, out, _ = run(capsys, "verify", cradle_file, "--u-plus", "0.5,0,0.5")  # γ₁⁺ < 0
    assert code == 1 and "kinematic  u⁺ ∈ T_C       residual" in out and "VIOLATED" in out
    code, _, err = run(capsys, "verify", dense_file)
    assert code == 2 and "no candidate u⁺" in err
    code, _, err = run(capsys, "verify", cradle_file, "--u-plus", "1,2")
    assert code == 2 and "--u-plus must have shape (3,)" in err


def test_verify_json(capsys, cradle_file):
    code, out, _ = run(capsys, "verify", cradle_file, "--u-plus", "0.2,0.2,0.2", "--json")
    report = json.loads(out)
    assert code == 1 and report["admissible"] is False
    assert report["failed"] == ["kinetic"]  # momentum is not conserved
    assert report["optimizer"]["admissible"] is False and report["optimizer"]["distance"] > 0.1
    assert set(report["conditions"]) == {"kinetic", "kinematic", "energetic"}


def test_parse_numbers():
    assert parse_numbers("--eps", "0.25") == 0.25
    np.testing.assert_array_equal(parse_numbers("--e", "0.5,1"), [0.5, 1.0])
    np.testing.assert_array_equal(parse_numbers("--E", "1,2;3,4"), [[1, 2], [3, 4]])


def test_plot_commands(capsys, tmp_path, cradle_file):
    for argv in (["plot", "cradle", "--out", tmp_path / "c.png"],
                 ["plot", "sectors", "--out", tmp_path / "s.svg"],
                 ["plot", "S", cradle_file, "--out", tmp_path / "S.png"],
                 ["plot", "cradle", "--out", tmp_path / "c.pdf"]):
        code, out, _ = run(capsys, *argv)
        assert code == 0 and out == f"wrote {argv[-1]}\n"
        assert argv[-1].stat().st_size > 5000
    assert (tmp_path / "c.pdf").read_bytes().startswith(b"%PDF")


def test_plot_draws_any_number_of_contacts_and_balls(capsys, tmp_path):
    heavy = iq.save_problem(iq.chain([1.0, 1.0, 1.0, 3.0], [1.0, 0.0, 0.0, 0.0]),
                            tmp_path / "heavy.json")
    four = iq.save_problem(iq.newtons_cradle(4), tmp_path / "four.json")
    for argv in (["plot", "S", heavy, "--out", tmp_path / "S4.png"],
                 ["plot", "sectors", four, "--out", tmp_path / "s4.png"],
                 ["plot", "sectors", "--balls", "5", "--out", tmp_path / "s5.png"],
                 ["plot", "sectors", "--masses", "1", "0.41421356237309503", "1",
                  "--out", tmp_path / "r3.png"]):
        code, out, err = run(capsys, *argv)
        assert (code, err) == (0, "") and out == f"wrote {argv[-1]}\n"
        assert argv[-1].read_bytes()[:4] == b"\x89PNG"
    code, _, err = run(capsys, "plot", "sectors", four, "--balls", "4", "--out",
                       tmp_path / "x.png")
    assert code == 2 and "not both" in err


def test_plot_refuses_to_overwrite_without_force(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, _ = run(capsys, "plot", "sectors")  # default output: ./sectors.png
    assert code == 0 and out == "wrote sectors.png\n"
    (tmp_path / "sectors.png").write_bytes(b"keep me")
    code, out, err = run(capsys, "plot", "sectors")
    assert code == 2 and out == "" and "sectors.png exists" in err and "--force" in err
    assert (tmp_path / "sectors.png").read_bytes() == b"keep me"
    code, out, _ = run(capsys, "plot", "sectors", "--force")
    assert code == 0 and (tmp_path / "sectors.png").read_bytes().startswith(b"\x89PNG")
    mine = tmp_path / "mine.svg"
    mine.write_text("mine")
    code, _, err = run(capsys, "plot", "cradle", "--out", mine)
    assert code == 2 and "exists" in err and mine.read_text() == "mine"


def test_plot_help_documents_the_default(capsys):
    with pytest.raises(SystemExit):
        cli.main(["plot", "cradle", "--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert "default: ./cradle.png" in out and "--force" in out and ".pdf" in out


def test_plot_errors_exit_2(capsys, tmp_path, monkeypatch):
    path = iq.save_problem(iq.newtons_cradle(3, v=-1.0), tmp_path / "away.json")
    code, _, err = run(capsys, "plot", "S", path, "--out", tmp_path / "x.png")
    assert code == 2 and "S = {u⁻}" in err
    heavy = iq.save_problem(iq.chain([1.0, 1.0, 1.0, 3.0], [1.0, 0.0, 0.0, 0.0]),
                            tmp_path / "heavy.json")
    code, _, err = run(capsys, "plot", "sectors", heavy, "--out", tmp_path / "x.png")
    assert code == 2 and "no continuous elastic law" in err and "45°" in err
    code, _, err = run(capsys, "plot", "cradle", "--out", tmp_path / "x.jpg")
    assert code == 2 and "must end in one of" in err
    monkeypatch.setitem(sys.modules, "matplotlib.figure", None)
    code, _, err = run(capsys, "plot", "sectors", "--out", tmp_path / "x.png")
    assert code == 2 and "pip install 'impactqp[plot]'" in err


def test_progress_reports_only_long_steps():
    quiet, loud = io.StringIO(), io.StringIO()
    with progress("quick", after=5.0, stream=quiet):
        pass
    with progress("slow step", after=0.01, every=0.02, stream=loud):
        time.sleep(0.1)
    assert quiet.getvalue() == ""
    assert loud.getvalue().startswith("impactqp: slow step… 0 s\n")
    assert loud.getvalue().count("slow step") >= 2


def test_verify_process_exit_status_without_matplotlib(cradle_file):
    script = ("import sys; from impactqp.cli import main; "
              f"rc = main(['verify', {str(cradle_file)!r}, '--u-plus', '1,0,0.5']); "
              "sys.exit(10 + rc if 'matplotlib' in sys.modules else rc)")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert done.returncode == 1 and "NOT ADMISSIBLE" in done.stdout
