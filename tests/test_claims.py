"""Claims that match what runs: no advertised suite times the benchmark does not measure, a
missed target never printed as "MISSED by 1.0×", explanations only of problems a summary ran,
angles printed to sensible digits, every example listed in the README, saved TOML arrays on
one line where they fit."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import tomllib

import impactqp as iq
from impactqp.io.save import TOML_LINE, problem_to_dict, to_toml

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


@pytest.mark.parametrize("factor, shown", [(1.3, "1.3"), (1.04, "1.04"), (1.001, "1.001"),
                                           (1.0400001, "1.04"), (25.0, "25.0")])
def test_a_miss_never_reads_as_one(factor: float, shown: str) -> None:
    from benchmarks.measure import missed_by
    from benchmarks.report import _at_most

    assert missed_by(factor) == f"MISSED by {shown}×"
    assert _at_most(factor * 2.0, 2.0) == f"MISSED by {shown}×"
    assert _at_most(2.0, 2.0) == "met"


def _agg(family, size, method, median, error=1e-12):
    return {"family": family, "size": size, "method": method, "group": "impactqp",
            "median_s": median, "max_error": error, "reference": "", "status": "ok",
            "success_rate": 1, "ok": 1, "ran": 1, "note": "", "message": ""}


def test_summary_explains_only_problems_it_ran() -> None:
    from benchmarks.friction import BASELINE, DEFAULT
    from benchmarks.report import summary_markdown, why_missed

    meta = {"suite": "quick", "seconds": 1, "timing_budget_s": 0, "max_repeats": 1,
            "accurate_below": 1e-6}
    quick = [_agg("friction:LMGC-00046", 9, DEFAULT, 1.04e-4),
             _agg("friction:LMGC-00046", 9, BASELINE, 1e-4)]
    text = summary_markdown(quick, meta)
    assert "MISSED" in text and "MISSED by 1.0×" not in text
    assert "LMGC-00046" in why_missed("friction", quick)
    for absent in ("KaplasTower", "NESpheres-10"):
        assert absent not in text.split("Why the missed targets are missed:")[1]
    full = [*quick, _agg("friction:KaplasTower", 570, DEFAULT, 1.5),
            _agg("friction:KaplasTower", 570, BASELINE, 1.0)]
    assert "KaplasTower (570 contacts" in why_missed("friction", full)


def test_friction_explanation_gives_its_own_runs_figures() -> None:
    """The reasons name only the problems this run found slow, with this run's ratio, and the
    fastest-solver sentence counts this run's winners."""
    from benchmarks.friction import BASELINE, DEFAULT
    from benchmarks.report import why_missed

    rows = [_agg("friction:LMGC-00046", 9, DEFAULT, 1.3e-4),
            _agg("friction:LMGC-00046", 9, BASELINE, 1e-4),
            _agg("friction:KaplasTower", 570, DEFAULT, 0.9),
            _agg("friction:KaplasTower", 570, BASELINE, 1.0)]
    text = why_missed("friction", rows)
    assert "on 1 problem:" in text and "LMGC-00046 (9 contacts, 1.30×)" in text
    assert "KaplasTower" not in text  # faster than NSGS in this run
    assert "siconos:NSGS on 1 " in text  # the one problem NSGS was the fastest on


def test_no_suite_time_is_advertised() -> None:
    """The suites' run time is what summary.md records; no fixed figure stands beside them."""
    texts = [README, *(p.read_text(encoding="utf-8") for p in (ROOT / "docs").glob("*.rst")),
             *(p.read_text(encoding="utf-8") for p in (ROOT / "benchmarks").glob("*.py"))]
    claim = re.compile(r"(smoke|quick)[^\n]*~\s*\d+\s*s\b")
    assert [m.group(0) for text in texts for m in claim.finditer(text)] == []


def test_readme_names_every_example() -> None:
    # every script and file of examples/ (GALLERY_HEADER.rst is the gallery's own page text)
    missing = [p.name for p in (ROOT / "examples").iterdir()
               if p.is_file() and p.name != "GALLERY_HEADER.rst" and p.name not in README]
    assert missing == []


def test_angles_print_to_sensible_digits() -> None:
    c = iq.classify(iq.newtons_cradle(3), [0, 0, 1.0])
    assert c.alpha_deg != 30 and np.isclose(c.alpha_deg, 30)  # computed, not exact
    assert repr(c) == "Classification(α = 30°, dissipation ε = 1, intensity 1.414)"
    quickstart = README.split("## Quickstart")[1].split("```\n")[0]
    assert "alpha_deg == 30" not in quickstart and "math.isclose(c.alpha_deg, 30)" in quickstart


def test_saved_toml_keeps_arrays_on_one_line(tmp_path: Path) -> None:
    M = np.diag([1.0, 2.0, 0.1 + 0.2])
    p = iq.ImpactProblem(M, [[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]], [1.0, 1e-300, -0.5])
    path = iq.save_problem(p, tmp_path / "p.toml", law="newton", coefficients=[1.0, 0.5])
    lines = path.read_text().splitlines()
    assert "M = [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 0.30000000000000004]]" in lines
    assert "u_minus = [1.0, 1e-300, -0.5]" in lines and "e = [1.0, 0.5]" in lines
    back = iq.load_problem(path).problem
    assert np.array_equal(back.M, M) and np.array_equal(back.u_minus, p.u_minus)
    # too long for one line: a vector wraps, several numbers a line, and reads back exactly
    chain = iq.newtons_cradle(60, v=1 / 3)
    text = to_toml(problem_to_dict(chain))
    assert max(map(len, text.splitlines())) <= TOML_LINE
    assert len(text.splitlines()) < 20
    assert tomllib.loads(text)["u_minus"] == chain.u_minus.tolist()
    # a matrix too wide for one line: one row a line
    wide = iq.ImpactProblem(np.eye(12) / 3, -np.eye(12)[:, :2] / 7, np.ones(12) / 3)
    text = to_toml(problem_to_dict(wide))
    rows = [line for line in text.splitlines() if line.startswith("    [")]
    assert len(rows) == 12 + 12  # M's 12 rows, then W's 12
    assert np.array_equal(np.array(tomllib.loads(text)["M"]), np.eye(12) / 3)
