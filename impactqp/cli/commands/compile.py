"""``impactqp compile``: compile every kernel ahead of time (for images, containers and
cluster workers that share the cache folder)."""

from __future__ import annotations

import argparse
import os
import sys


def run(args: argparse.Namespace) -> int:
    from tqdm import tqdm

    from ...precompile import STAGES, compile_kernels

    with tqdm(total=len(STAGES), unit="stage", file=sys.stderr,
              disable=args.quiet or not sys.stderr.isatty()) as bar:
        def progress(stage: str, done: int, total: int) -> None:
            bar.set_description(stage)
            bar.n = done
            bar.refresh()

        report = compile_kernels(progress, jobs=args.jobs)
    print(report.summary())
    if args.list:
        for name in report.compiled:
            print(f"  compiled     {name}")
        for name in report.not_reached:
            print(f"  inside       {name} (compiled into the kernels that call it)")
    return 0


def _cores() -> int:
    """Cores this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0))
    return os.cpu_count() or 1


def _positive(text: str) -> int:
    """A positive integer, or argparse's error naming the flag."""
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a positive integer, got {text!r}")
    return value


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("compile", help="compile every numba kernel now, into the cache folder")
    p.add_argument("--list", action="store_true",
                   help="list the kernels compiled on their own and those compiled into "
                        "their callers")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--jobs", type=_positive, default=_cores(),
                   help="processes compiling at once (default: one per core of this "
                        "process)")
    p.set_defaults(func=run)
