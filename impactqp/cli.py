"""Command-line entry point ``impactqp``."""

from __future__ import annotations

import argparse
import sys

from .errors import ImpactError


def _demo(args: argparse.Namespace) -> int:
    from .demo import cradle_rows, format_rows

    print(f"Newton's cradle, {args.balls} balls, ball 1 released at v = {args.v:g} (unit masses)")
    print(format_rows(cradle_rows(n_balls=args.balls, v=args.v, backend=args.backend)))
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="impactqp",
                                     description="Rigid-body impacts as convex programs.")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="Newton's cradle through Moreau's law, verified")
    demo.add_argument("--balls", type=int, default=3, help="number of balls (default 3)")
    demo.add_argument("--v", type=float, default=1.0, help="speed of the released ball")
    demo.add_argument("--backend", default="auto", help="QP backend (default auto)")
    demo.set_defaults(func=_demo)
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
