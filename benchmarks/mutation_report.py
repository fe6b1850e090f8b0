"""The mutation run's Markdown report: per module the mutants and their fate, which test
killed which mutant, and every surviving mutant with its diff."""

from __future__ import annotations

from collections import Counter
from typing import Any

STATUSES = ("killed", "timeout", "survived", "equivalent", "error", "no-test")


def score(records: list[dict[str, Any]]) -> tuple[int, int]:
    """(detected, judged): mutants killed or timed out, among those not equivalent and
    actually tested."""
    counts = Counter(r["status"] for r in records)
    detected = counts["killed"] + counts["timeout"]
    return detected, detected + counts["survived"] + counts["error"]


def _pct(detected: int, judged: int) -> str:
    return f"{100.0 * detected / judged:.0f}%" if judged else "—"


def _sample(mod: dict[str, Any]) -> str:
    return "all" if mod.get("sample") is None else f"{mod['sample']} (seed {mod['seed']})"


def _name(record: dict[str, Any]) -> str:
    return (f"line {record['line']} {record['operator'].removeprefix('core/')}"
            f" #{record['occurrence']}")


def summary_markdown(results: dict[str, Any]) -> str:
    """The report of one run (``results`` as :func:`benchmarks.mutation.run` returns it)."""
    modules = results["modules"]
    every = [r for mod in modules for r in mod["results"]]
    detected, judged = score(every)
    lines = [
        "# impactqp mutation checks",
        "",
        "`python -m benchmarks.mutation` — each mutant is one change by cosmic-ray's "
        "operators (listed in benchmarks/mutation_config.py) in a scratch copy; the module's "
        "test files then run with `NUMBA_DISABLE_JIT=1` and `pytest -x`. killed = a test "
        "failed (the first one is named below); timeout = the tests ran past 4× the "
        "unmutated run (≥ 60 s); equivalent = survived, and no input can tell it from the "
        "original (reason below); score = (killed + timeout) / (mutants run − equivalent). "
        "run = mutants run: all of the module's, or a seeded random sample (column sample).",
        "",
        f"**Overall: {detected} of {judged} non-equivalent mutants detected "
        f"({_pct(detected, judged)}), run time "
        f"{sum(mod.get('run_s', 0.0) for mod in modules):.0f} s.**",
        "",
        "| module | mutants | sample | run | killed | timeout | survived | equivalent | error "
        "| score | tests | unmutated run |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for mod in modules:
        counts = Counter(r["status"] for r in mod["results"])
        d, j = score(mod["results"])
        tests = ", ".join(t.removeprefix("tests/") for t in mod["tests"])
        lines.append(
            f"| {mod['module']} | {mod['mutants']} | {_sample(mod)} | {len(mod['results'])} "
            f"| {counts['killed']} | {counts['timeout']} | {counts['survived']} "
            f"| {counts['equivalent']} | {counts['error']} | {_pct(d, j)} | {tests} "
            f"| {mod['baseline_s']:.1f} s |")
    for mod in modules:
        lines += ["", f"## {mod['module']}", ""]
        killers = Counter(r["killer"] for r in mod["results"] if r["status"] == "killed")
        if killers:
            lines += ["Tests that killed mutants (first failure under `-x`):", "",
                      "| test | mutants killed |", "|---|---|"]
            lines += [f"| `{test}` | {n} |" for test, n in killers.most_common()]
            lines += ["", "<details><summary>which test killed which mutant</summary>", "",
                      "| mutant | status | killed by |", "|---|---|---|"]
            lines += [f"| {_name(r)} | {r['status']} | `{r['killer']}` |"
                      for r in mod["results"] if r["status"] in ("killed", "timeout")]
            lines += ["", "</details>"]
        for status, title in (("survived", "Surviving mutants"), ("error", "Mutants in error"),
                              ("equivalent", "Equivalent mutants")):
            chosen = [r for r in mod["results"] if r["status"] == status]
            if not chosen:
                continue
            lines += ["", f"### {title}", ""]
            for r in chosen:
                why = f" — {r['reason']}" if r["reason"] else ""
                why += f" — {r['killer']}" if status == "error" else ""
                lines += [f"- {_name(r)}{why}", "", "```diff", *_hunk(r["diff"]), "```", ""]
    return "\n".join(lines).rstrip() + "\n"


def _hunk(diff: str) -> list[str]:
    """The diff without its file header lines."""
    return [ln for ln in diff.splitlines() if not ln.startswith(("---", "+++"))]
