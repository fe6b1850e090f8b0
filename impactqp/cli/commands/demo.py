"""``impactqp demo``: the 3-ball cradle through Moreau's law, verified and classified."""

from __future__ import annotations

import argparse


def run(args: argparse.Namespace) -> int:
    from ..demo import cradle_rows, format_rows

    rows = cradle_rows(n_balls=args.balls, v=args.v, backend=args.backend)
    print(f"Newton's cradle, {args.balls} balls, ball 1 released at v = {args.v:g} (unit masses)")
    print(format_rows(rows))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("demo", help="Newton's cradle through Moreau's law, verified")
    p.add_argument("--balls", type=int, default=3, help="number of balls (default 3)")
    p.add_argument("--v", type=float, default=1.0, help="speed of the released ball")
    p.add_argument("--backend", default="auto", help="QP backend (default auto)")
    p.set_defaults(func=run)
