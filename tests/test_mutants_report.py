"""The mutation run's bookkeeping (benchmarks/mutation.py, mutation_report.py): the seeded
sample, the equivalence key, the score and the report."""

from __future__ import annotations

import random
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.mutation import Mutant, _changed_lines, sample  # noqa: E402
from benchmarks.mutation_config import EQUIVALENT, FIRST, MODULES, OPERATORS  # noqa: E402
from benchmarks.mutation_report import score, summary_markdown  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _record(status: str, line: int, killer: str = "", reason: str = "") -> dict:
    diff = f"--- a\n+++ b\n@@ -{line} +{line} @@\n-x = a + b\n+x = a - b\n"
    return {"module": "m.py", "operator": "core/ReplaceBinaryOperator_Add_Sub", "occurrence": 0,
            "line": line, "status": status, "killer": killer, "diff": diff, "seconds": 1.0,
            "reason": reason}


def test_score_counts_detected_among_the_non_equivalent() -> None:
    records = [_record("killed", 1, "t::a"), _record("timeout", 2), _record("survived", 3),
               _record("equivalent", 4, reason="same float"), _record("no-test", 5)]
    assert score(records) == (2, 3)
    assert score([]) == (0, 0)


def test_report_names_killers_survivors_and_reasons() -> None:
    results = {"operators": list(OPERATORS),
               "modules": [{"module": "m.py", "tests": ["tests/test_a.py"], "mutants": 9,
                            "baseline_s": 2.0, "timeout_s": 60.0, "sample": 5, "seed": 3,
                            "run_s": 12.0,
                            "results": [_record("killed", 1, "tests/test_a.py::t"),
                                        _record("killed", 2, "tests/test_a.py::t"),
                                        _record("survived", 7),
                                        _record("equivalent", 8, reason="same float")]}]}
    text = summary_markdown(results)
    assert "2 of 3 non-equivalent mutants detected (67%), run time 12 s" in text
    assert "| m.py | 9 | 5 (seed 3) | 4 | 2 | 0 | 1 | 1 | 0 | 67% | test_a.py | 2.0 s |" in text
    assert "| `tests/test_a.py::t` | 2 |" in text
    survivors = text.split("### Surviving mutants")[1].split("###")[0]
    assert "line 7" in survivors and "+x = a - b" in survivors and "line 1 " not in survivors
    assert "same float" in text.split("### Equivalent mutants")[1]


def test_sample_is_seeded_and_in_source_order() -> None:
    mutants = [Mutant("m.py", "op", k, line=100 - k) for k in range(50)]
    a = sample(mutants, 10, random.Random(4))
    b = sample(mutants, 10, random.Random(4))
    assert [m.occurrence for m in a] == [m.occurrence for m in b]
    assert [m.line for m in a] == sorted(m.line for m in a)
    assert len({m.occurrence for m in a}) == 10
    assert len(sample(mutants, None, random.Random(0))) == 50
    assert len(sample(mutants, 80, random.Random(0))) == 50


def test_the_equivalence_key_is_the_changed_lines() -> None:
    diff = "--- a/m.py\n+++ b/m.py\n@@ -1 +1 @@\n-    y = 1e100\n+    y = 1e+100\n"
    assert _changed_lines(diff) == ("y = 1e100", "y = 1e+100")
    for module, operator, before, after in EQUIVALENT:
        assert module in MODULES and operator in OPERATORS
        assert before in (ROOT / module).read_text(encoding="utf-8")
        assert before != after


def test_the_table_names_existing_modules_and_tests() -> None:
    assert set(FIRST) <= set(MODULES)
    for module, tests in MODULES.items():
        assert (ROOT / module).is_file(), module
        assert all((ROOT / t).is_file() for t in tests), tests


def test_mutants_of_the_verdict_module() -> None:
    pytest.importorskip("cosmic_ray")  # the optional ``mutation`` extra
    from benchmarks.mutation import enumerate_mutants

    mutants = enumerate_mutants("impactqp/base/checks.py")
    assert mutants and all(m.operator in OPERATORS for m in mutants)
    # the verdict's comparison ``v <= self.tol`` is among the mutated lines
    text = (ROOT / "impactqp/base/checks.py").read_text(encoding="utf-8").splitlines()
    assert any("v <= self.tol" in text[m.line - 1] for m in mutants)


def test_rejudge_applies_the_tables_to_a_finished_run(tmp_path: Path) -> None:
    import json

    from benchmarks.mutation import rejudge

    (module, operator, before, after), reason = next(iter(EQUIVALENT.items()))
    explained = _record("survived", 3) | {
        "module": module, "operator": operator,
        "diff": f"--- a\n+++ b\n@@ -3 +3 @@\n-{before}\n+{after}\n"}
    results = {"operators": list(OPERATORS),
               "modules": [{"module": module, "tests": [], "mutants": 2, "baseline_s": 1.0,
                            "timeout_s": 60.0, "sample": None, "seed": 0, "run_s": 2.0,
                            "results": [explained, _record("survived", 9)]}]}
    (tmp_path / "results.json").write_text(json.dumps(results), encoding="utf-8")
    records = rejudge(tmp_path)["modules"][0]["results"]
    assert [r["status"] for r in records] == ["equivalent", "survived"]
    assert records[0]["reason"] == reason
    assert "1 of 1" not in (tmp_path / "summary.md").read_text(encoding="utf-8")
    assert "0 of 1 non-equivalent" in (tmp_path / "summary.md").read_text(encoding="utf-8")
