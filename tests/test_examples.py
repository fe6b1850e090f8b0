"""Every script in examples/ runs as a stranger would run it, prints what it promises, and
writes only into the folder it prints (never into the working directory or the clone)."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

EXPECTED = {
    "cradle.py": ["sector law    (+0.000, +0.000, +1.000)", "Moreau ε = 1",
                  "30.0"],
    "verify_custom_law.py": ["equal masses (1, 1, 1), ImpactLaw: ok",
                             "masses (1, 2, 1), callable: VIOLATED",
                             "worst counterexample (non_expansive"],
    "benchmark_run.py": ["# impactqp benchmark — suite `smoke`", "## Targets"],
    "lzb_comparison.py": ["3 balls, u⁻ = (1, 0, …, 0) m/s", "10 balls"],
    "simulate_cradle.py": ["cradle.gif"],
    "figures.py": ["the sphere rolls from t = 0.195 s (2v₀/(7μg) = 0.194 s)",
                   "S of the heavy 4-ball cradle: 3 contacts", "sectors_4_balls.png"],
    "identify_restitution.py": ["event-driven, Gauss–Newton from e = 0.5",
                                "moreau-jean, Gauss–Newton from e = 0.5",
                                "  e = 0.730000000, |e - e*|", "(flow, 0 kinks)",
                                "(discrete-map, 0 kinks)", "  ε = 0.600000000, |ε - ε*|"],
    "friction.py": ["sphere on the floor", " 0.05  slip ", "  0.3  stick ",
                    "FCLib LMGC_GlobalFrictionContactProblem00046.hdf5: 9 contacts, d = 3",
                    "certificate ok at tol 1e-08"],
}

WRITES = {
    "benchmark_run.py": {"results.csv", "results.json", "summary.md", "plot.png"},
    "lzb_comparison.py": {"lzb_comparison.png"},
    "simulate_cradle.py": {"bouncing_ball_energy.png", "cradle_positions.png", "cradle.gif"},
    "figures.py": {"sphere_positions.png", "sphere_contacts.png", "sphere.gif",
                   "S_heavy_cradle.png", "sectors_4_balls.png"},
}
"""The files each writing example leaves in the folder it prints last."""

SCRIPTS = sorted(p.name for p in EXAMPLES.glob("*.py"))


def _run(name: str, cwd: Path, *args: str) -> subprocess.CompletedProcess:
    done = subprocess.run([sys.executable, str(EXAMPLES / name), *args], capture_output=True,
                          text=True, timeout=180, cwd=cwd)
    assert done.returncode == 0, done.stderr
    return done


def _printed_folder(stdout: str) -> Path:
    match = re.search(r"written to (.+)$", stdout.strip().splitlines()[-1])
    assert match, stdout
    return Path(match.group(1))


def test_the_documented_examples_exist():
    assert set(EXPECTED) == set(SCRIPTS) and set(WRITES) <= set(SCRIPTS)


def _repository_state() -> str:
    root = EXAMPLES.parent
    if not (root / ".git").exists() or shutil.which("git") is None:
        return ""
    return subprocess.run(["git", "status", "--porcelain", "--untracked-files=all"], cwd=root,
                          capture_output=True, text=True).stdout


@pytest.mark.parametrize("name", SCRIPTS)
def test_example_runs(name, tmp_path):
    """Every script runs from a foreign working directory, prints its key lines and leaves
    nothing behind there; one that writes files names its folder last, and that folder (a new
    temporary one by default) holds exactly what it promised."""
    before = _repository_state()
    done = _run(name, tmp_path)
    for line in EXPECTED[name]:
        assert line in done.stdout, (line, done.stdout)
    assert not list(tmp_path.iterdir())  # nothing left behind in the working directory
    assert _repository_state() == before  # nor in the clone (docs/figures untouched)
    if name in WRITES:
        folder = _printed_folder(done.stdout)
        try:
            assert folder.is_absolute() and not folder.is_relative_to(EXAMPLES.parent)
            assert {p.name for p in folder.iterdir()} == WRITES[name]
        finally:
            shutil.rmtree(folder)


@pytest.mark.parametrize("name", sorted(set(WRITES) - {"benchmark_run.py"}))
def test_example_writes_where_it_is_told(name, tmp_path):
    """``--out DIR`` puts the files in DIR (created), and nowhere else."""
    done = _run(name, tmp_path, "--out", "figs")
    assert _printed_folder(done.stdout) == Path("figs")
    assert [p.name for p in tmp_path.iterdir()] == ["figs"]
    assert {p.name for p in (tmp_path / "figs").iterdir()} == WRITES[name]


def test_friction_example_agrees_with_its_closed_form_and_writes_only_when_told(tmp_path):
    """Every μ's u⁺ matches the stick/slip closed form printed beside it; nothing is written
    without ``--out``, the sphere's problem file (law coulomb) with it."""
    import impactqp as iq

    done = _run("friction.py", tmp_path, "--out", "out")
    rows = [line.split() for line in done.stdout.splitlines()
            if line.split()[1:2] in (["stick"], ["slip"])]
    assert [(row[0], row[1]) for row in rows] == [("0.0", "slip"), ("0.05", "slip"),
                                                  ("0.3", "stick")]
    assert all(float(row[-3]) < 1e-9 and row[-2:] == ["ok", "yes"] for row in rows)
    assert _printed_folder(done.stdout) == Path("out")
    assert [p.name for p in tmp_path.iterdir()] == ["out"]
    content = iq.load_problem(tmp_path / "out" / "sphere_on_plane.toml")
    assert content.law == "coulomb" and content.coefficients == (0.3, 0.5)
    assert content.problem.contact_dim == 2


def test_identification_example_writes_its_fit_only_when_told(tmp_path):
    """``--out`` writes fit.json (the three identified coefficients) and nothing else."""
    import json

    done = _run("identify_restitution.py", tmp_path, "--out", "out")
    assert _printed_folder(done.stdout) == Path("out")
    fits = json.loads((tmp_path / "out" / "fit.json").read_text())
    assert fits["event-driven"] == pytest.approx(0.73, abs=1e-6)
    assert fits["moreau-jean"] == pytest.approx(0.73, abs=1e-6)
    assert fits["cradle eps"] == pytest.approx(0.6, abs=1e-6)
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["fit.json"]
