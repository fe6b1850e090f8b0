"""Command-line entry point ``impactqp``: each subcommand lives in :mod:`impactqp.commands`."""

from __future__ import annotations

import argparse
import sys

from importlib.metadata import PackageNotFoundError, version

from ..errors import ImpactError
from .commands import demo, plot, sector, solve, verify

COMMANDS = [demo, solve, verify, plot, sector]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="impactqp",
                                     description="Rigid-body impacts as convex programs.")
    try:
        installed = version("impactqp")
    except PackageNotFoundError:
        installed = "0+unknown"
    parser.add_argument("--version", action="version", version=f"impactqp {installed}")
    sub = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the ``impactqp`` command; return its exit status (2 for bad input)."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except ImpactError as exc:
        print(f"impactqp: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
