"""Every script in examples/ runs as a stranger would run it and prints what it promises."""

from __future__ import annotations

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
}


SCRIPTS = sorted(p.name for p in EXAMPLES.glob("*.py"))


def test_the_documented_examples_exist():
    assert set(EXPECTED) <= set(SCRIPTS)


@pytest.mark.parametrize("name", SCRIPTS)
def test_example_runs(name, tmp_path):
    """Every script runs from a foreign working directory and prints something; the
    documented ones print their key lines and leave nothing behind."""
    done = subprocess.run([sys.executable, str(EXAMPLES / name)], capture_output=True,
                          text=True, timeout=120, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip()
    for line in EXPECTED.get(name, []):
        assert line in done.stdout, (line, done.stdout)
    if name in EXPECTED:
        assert not list(tmp_path.iterdir())  # nothing left behind in the working directory
