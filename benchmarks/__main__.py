"""``python -m benchmarks run --suite smoke|quick|full|friction [--out DIR] [--n-jobs N]
[--merge]``, and ``python -m benchmarks run --suite fclib --collection DIR [--scheduler
ADDRESS] [--time-limit S] [--output FILE]`` (a whole folder of friction problems,
:mod:`benchmarks.collection`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .families import SUITES
from .peers import SICONOS_PYTHON
from .runner import run_suite


def _jobs(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"--n-jobs must be at least 1, got {value}")
    return value


def _seconds(text: str) -> float:
    value = float(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"--time-limit must be positive, got {text}")
    return value


def _collection(args: argparse.Namespace) -> int:
    """The ``fclib`` suite: a collection's records, then their summary."""
    from .collection import run_fclib_collection, summary

    output = args.output or args.out / "fclib_collection.jsonl"
    records = run_fclib_collection(
        args.collection, output, methods=args.methods.split(","), time_limit=args.time_limit,
        n_jobs=args.n_jobs, scheduler=args.scheduler, siconos_python=args.siconos_python,
        progress=None if args.no_progress else lambda line: print(line, file=sys.stderr))
    print(summary(records, output.with_suffix(".png")))
    print(f"records in {output}")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Parse the command line and run a suite; return the exit status."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks",
                                     description="Time impactqp against raw solvers and Siconos.")
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run a benchmark suite")
    run.add_argument("--suite", choices=sorted([*SUITES, "fclib"]), default="quick",
                     help="fclib: every problem file of --collection")
    run.add_argument("--out", type=Path, default=Path("benchmarks/results"),
                     help="output directory (default: benchmarks/results)")
    run.add_argument("--siconos-python", default=SICONOS_PYTHON,
                     help="interpreter that imports siconos ('' skips the peer)")
    run.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")
    run.add_argument("--n-jobs", type=_jobs, default=2,
                     help="local processes of the sweep benchmark, timed against one, "
                          "and of --suite fclib without --scheduler (default 2)")
    run.add_argument("--merge", action="store_true",
                     help="replace only this suite's families in the results already in --out "
                          "(e.g. --suite friction --out benchmarks/reference)")
    fclib = run.add_argument_group("--suite fclib")
    fclib.add_argument("--collection", type=Path, help="folder of FCLib/Siconos files")
    fclib.add_argument("--scheduler", help="dask.distributed scheduler address (default: "
                       "local, --n-jobs processes)")
    fclib.add_argument("--time-limit", type=_seconds, help="seconds per problem and method")
    fclib.add_argument("--output", type=Path, help="JSON Lines records, resumed when "
                       "present (default: OUT/fclib_collection.jsonl)")
    fclib.add_argument("--methods", default="auto",
                       help="impactqp's methods, comma-separated (default: auto)")
    args = parser.parse_args(argv)
    if args.suite == "fclib":
        if args.collection is None:
            parser.error("--suite fclib needs --collection DIR")
        return _collection(args)
    if args.collection is not None:
        parser.error("--collection goes with --suite fclib")
    if args.merge and not (args.out / "results.json").is_file():
        parser.error(f"--merge needs {args.out}/results.json to merge into")
    run_suite(args.suite, args.out, siconos_python=args.siconos_python,
              progress=not args.no_progress, n_jobs=args.n_jobs, merge=args.merge)
    extra = ", friction_profile.png" if (args.out / "friction_profile.png").exists() else ""
    print(f"wrote {args.out}/results.csv, results.json, summary.md, plot.png{extra}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
