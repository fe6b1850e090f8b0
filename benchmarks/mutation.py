"""``python -m benchmarks.mutation [--modules PATH ...] [--sample N] [--seed S] [--out DIR]
[--merge] [--rejudge] [--list]``: mutation checks of the modules holding formulas and verdicts.

Each mutant is one small change made by cosmic-ray's operators (:data:`.mutation_config.
OPERATORS`) to one module, in a scratch copy of the repository; the module's fast test files
(:data:`.mutation_config.MODULES`) are then run with ``NUMBA_DISABLE_JIT=1``, so that a mutated
kernel runs as plain Python and no mutant waits for numba to compile. A mutant is *killed* when
a test fails (the first failing test is recorded), *timeout* when the tests run past their
limit, *survived* when they all pass, *equivalent* when it survived and
:data:`.mutation_config.EQUIVALENT` explains why no input can tell it from the original.

cosmic-ray rather than mutmut: cosmic-ray writes each mutant into the module's file and runs
an ordinary test command, which is what numba's kernels need (with the JIT disabled they are
the file's own functions); mutmut 3 rewrites every function into a trampoline that dispatches
between variants at run time, which the ``@kernel`` decorators and the compiled paths do not
go through. Needs the ``mutation`` extra (``pip install -e .[mutation]``).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import shutil
import sys
import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from .mutation_config import EQUIVALENT, FIRST, MODULES, NOTES, OPERATORS
from .mutation_report import summary_markdown

ROOT = Path(__file__).resolve().parent.parent
COPIED = ("impactqp", "tests", "docs", "examples", "benchmarks", "README.md", "pyproject.toml")
"""What the scratch copy holds: the package and what its tests read."""

_FAILED = re.compile(r"^(?:FAILED|ERROR) (\S+)", re.MULTILINE)


@dataclass
class Mutant:
    """One mutant and what the tests made of it."""

    module: str
    operator: str
    occurrence: int
    line: int
    status: str = "pending"
    killer: str = ""
    diff: str = ""
    seconds: float = 0.0
    reason: str = ""


def _cosmic_ray():
    try:
        import cosmic_ray.plugins  # noqa: F401
        from cosmic_ray.ast import ast_nodes, get_ast_from_path
        from cosmic_ray.mutating import mutate_and_test
        from cosmic_ray.work_item import MutationSpec, TestOutcome, WorkerOutcome
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise SystemExit("the mutation run needs cosmic-ray: pip install -e .[mutation]") from exc
    return (cosmic_ray.plugins, ast_nodes, get_ast_from_path, mutate_and_test, MutationSpec,
            TestOutcome, WorkerOutcome)


def enumerate_mutants(module: str, root: Path = ROOT) -> list[Mutant]:
    """Every mutant of ``module`` (a path from ``root``) that :data:`OPERATORS` make, in
    cosmic-ray's order (operator, then position)."""
    plugins, ast_nodes, get_ast_from_path, *_ = _cosmic_ray()
    tree = get_ast_from_path(root / module)
    nodes = list(ast_nodes(tree))
    mutants = []
    for name in OPERATORS:
        operator = plugins.get_operator(name)()
        positions = [start for node in nodes for start, _ in operator.mutation_positions(node)]
        mutants += [Mutant(module, name, k, start[0]) for k, start in enumerate(positions)]
    return mutants


def sample(mutants: list[Mutant], n: int | None, rng: random.Random) -> list[Mutant]:
    """``n`` of ``mutants`` drawn by ``rng`` (all when ``n`` is None), in source order."""
    chosen = mutants if n is None or n >= len(mutants) else rng.sample(mutants, n)
    return sorted(chosen, key=lambda m: (m.line, m.operator, m.occurrence))


def _test_command(tests: tuple[str, ...]) -> str:
    return f"{sys.executable} -m pytest -x -q -p no:cacheprovider -rfE " + " ".join(tests)


def _changed_lines(diff: str) -> tuple[str, str]:
    before = [ln[1:].strip() for ln in diff.splitlines()
              if ln.startswith("-") and not ln.startswith("---")]
    after = [ln[1:].strip() for ln in diff.splitlines()
             if ln.startswith("+") and not ln.startswith("+++")]
    return " / ".join(before), " / ".join(after)


def _explain(record: dict) -> None:
    """Mark a surviving record equivalent or noted by the tables (``record`` as in
    results.json)."""
    key = (record["module"], record["operator"], *_changed_lines(record["diff"]))
    record["status"] = "equivalent" if key in EQUIVALENT else "survived"
    record["reason"] = EQUIVALENT.get(key, NOTES.get(key, ""))


def rejudge(out: Path) -> dict:
    """Apply the current :data:`EQUIVALENT` and :data:`NOTES` to the survivors of the run in
    ``out`` and rewrite its report, without running anything."""
    results = json.loads((out / "results.json").read_text(encoding="utf-8"))
    for record in (r for mod in results["modules"] for r in mod["results"]):
        if record["status"] in ("survived", "equivalent"):
            _explain(record)
    (out / "results.json").write_text(json.dumps(results, indent=1) + "\n", encoding="utf-8")
    (out / "summary.md").write_text(summary_markdown(results), encoding="utf-8")
    return results


def _judge(mutant: Mutant, result, test_outcome) -> None:
    mutant.diff = result.diff or ""
    if result.test_outcome is None:
        mutant.status = "no-test"
        return
    if result.test_outcome == test_outcome.INCOMPETENT:
        mutant.status, mutant.killer = "error", (result.output or "").strip().splitlines()[-1:][0]
        return
    if result.test_outcome == test_outcome.SURVIVED:
        record = asdict(mutant)
        _explain(record)
        mutant.status, mutant.reason = record["status"], record["reason"]
        return
    if result.output == "timeout":
        mutant.status = "timeout"
        return
    found = _FAILED.search(result.output or "")
    mutant.status = "killed"
    mutant.killer = found.group(1) if found else "non-zero exit (no test named)"


def _scratch_copy() -> Path:
    scratch = Path(tempfile.mkdtemp(prefix="impactqp-mutation-"))
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "results", "_build")
    for name in COPIED:
        source = ROOT / name
        if source.is_dir():
            shutil.copytree(source, scratch / name, ignore=ignore)
        elif source.exists():
            shutil.copy2(source, scratch / name)
    return scratch


def _baseline(tests: tuple[str, ...]) -> float:
    """Seconds the unmutated tests take; exits when they do not pass."""
    from cosmic_ray.testing import run_tests
    from cosmic_ray.work_item import TestOutcome

    start = time.perf_counter()
    outcome, output = run_tests(_test_command(tests), timeout=900)
    if outcome != TestOutcome.SURVIVED:
        raise SystemExit(f"the unmutated tests fail, nothing to judge mutants by:\n{output}")
    return time.perf_counter() - start


def run(modules: list[str], n: int | None, seed: int, out: Path, progress: bool = True,
        merge: bool = False) -> dict:
    """Run the mutants of ``modules`` (``n`` drawn per module with ``seed``, or all) and write
    ``summary.md`` and ``results.json`` in ``out`` (with ``merge``, replacing only these
    modules' results in the ones already there); return the results."""
    *_, mutate_and_test, mutation_spec, test_outcome, _ = _cosmic_ray()
    start = time.perf_counter()
    scratch = _scratch_copy()
    here = Path.cwd()
    os.environ["NUMBA_DISABLE_JIT"] = "1"
    os.environ["PYTHONPATH"] = str(scratch)
    os.chdir(scratch)
    per_module = []
    try:
        for module in modules:
            tests = MODULES[module]
            every = enumerate_mutants(module, scratch)
            chosen = sample(every, n, random.Random(f"{seed}:{module}"))  # per module
            base = _baseline(tests)
            timeout = max(60.0, 4.0 * base)
            for k, mutant in enumerate(chosen, 1):
                spec = mutation_spec(module_path=scratch / module, operator_name=mutant.operator,
                                     occurrence=mutant.occurrence, start_pos=(mutant.line, 0),
                                     end_pos=(mutant.line, 1))
                t0 = time.perf_counter()
                result = mutate_and_test([spec], _test_command(tests), timeout)
                mutant.seconds = time.perf_counter() - t0
                _judge(mutant, result, test_outcome)
                if progress:
                    print(f"[{module} {k}/{len(chosen)}] {mutant.status:10s} "
                          f"{mutant.operator.removeprefix('core/')} line {mutant.line} "
                          f"{mutant.killer}", file=sys.stderr, flush=True)
            per_module.append({"module": module, "tests": list(tests), "mutants": len(every),
                               "baseline_s": base, "timeout_s": timeout,
                               "results": [asdict(m) for m in chosen]})
    finally:
        os.chdir(here)
        shutil.rmtree(scratch, ignore_errors=True)
    seconds = time.perf_counter() - start
    for record in per_module:
        record.update(sample=n, seed=seed, run_s=seconds * len(record["results"])
                      / max(1, sum(len(r["results"]) for r in per_module)))
    results = {"operators": list(OPERATORS), "modules": per_module}
    if merge and (out / "results.json").is_file():
        earlier = json.loads((out / "results.json").read_text(encoding="utf-8"))["modules"]
        results["modules"] = [r for r in earlier if r["module"] not in modules] + per_module
    out.mkdir(parents=True, exist_ok=True)
    (out / "results.json").write_text(json.dumps(results, indent=1) + "\n", encoding="utf-8")
    (out / "summary.md").write_text(summary_markdown(results), encoding="utf-8")
    return results


def main(argv: list[str] | None = None) -> int:
    """Parse the command line, run the mutants, print where the report is; the exit status
    is 1 when a mutant survived that neither :data:`EQUIVALENT` nor :data:`NOTES` explains,
    or could not be run."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks.mutation",
                                     description="Mutation checks of impactqp's formulas "
                                                 "and verdicts.")
    parser.add_argument("--modules", nargs="+", choices=sorted(MODULES), default=list(FIRST),
                        metavar="PATH", help="modules to mutate (default: "
                                             + ", ".join(FIRST) + ")")
    parser.add_argument("--sample", type=int, default=None, metavar="N",
                        help="run N mutants per module drawn at random (default: all)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the sample (default 0)")
    parser.add_argument("--out", type=Path, default=Path("benchmarks/results/mutation"),
                        help="output directory (default: benchmarks/results/mutation)")
    parser.add_argument("--merge", action="store_true",
                        help="replace only these modules' results in --out's results.json")
    parser.add_argument("--rejudge", action="store_true",
                        help="apply the current EQUIVALENT and NOTES tables to --out's "
                             "results.json and rewrite its report, running nothing")
    parser.add_argument("--list", action="store_true",
                        help="print how many mutants each module has and stop")
    parser.add_argument("--no-progress", action="store_true", help="no line per mutant")
    args = parser.parse_args(argv)
    if args.sample is not None and args.sample < 1:
        parser.error(f"--sample must be at least 1, got {args.sample}")
    if args.list:
        for module in args.modules:
            print(f"{module}: {len(enumerate_mutants(module))} mutants; tests: "
                  + " ".join(MODULES[module]))
        return 0
    if args.rejudge:
        results = rejudge(args.out)
    else:
        results = run(args.modules, args.sample, args.seed, args.out.resolve(),
                      progress=not args.no_progress, merge=args.merge)
    print(f"wrote {args.out}/summary.md, results.json")
    survived = [m for mod in results["modules"] for m in mod["results"]
                if m["status"] == "error" or (m["status"] == "survived" and not m["reason"])]
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
