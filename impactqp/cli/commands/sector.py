"""``impactqp sector-law``: the sector law's cone table and its exact certificate (docs/theory.md
§6, §7)."""

from __future__ import annotations

import argparse


def run(args: argparse.Namespace) -> int:
    from ...tables.sector_table import format_sector_table, sector_law_table

    table = sector_law_table(n_balls=args.balls, mass=args.mass)
    print(format_sector_table(table))
    return 0 if table.certificate.maximal_monotone else 1


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sector-law", help="cone table of the sector law, exactly certified")
    p.add_argument("--balls", type=int, default=3, help="number of equal balls, 2..8 (default 3)")
    p.add_argument("--mass", type=float, default=1.0, help="mass of every ball (default 1)")
    p.set_defaults(func=run)
