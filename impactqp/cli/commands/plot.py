"""``impactqp plot cradle|sectors|S FILE``: the figures of docs/theory.md §5 and docs/theory.md §6
as PNG or SVG.

Needs the optional extra ``plot`` (matplotlib).
"""

from __future__ import annotations

import argparse

from ...io.files import load_problem


def run_cradle(args: argparse.Namespace) -> int:
    from ...figures.plots import plot_cradle

    print(f"wrote {plot_cradle(args.out, v=args.v)}")
    return 0


def run_sectors(args: argparse.Namespace) -> int:
    from ...figures.plots import plot_sectors

    print(f"wrote {plot_sectors(args.out)}")
    return 0


def run_S(args: argparse.Namespace) -> int:
    from ...figures.plots import plot_S
    from .solve import solve_law

    content = load_problem(args.file)
    marks = {}
    if content.law is not None:
        result = solve_law(content.problem, content.law, content.coefficients)
        marks[f"{content.law} law u⁺"] = result.u_plus
    if content.u_plus is not None:
        marks["u_plus of the file"] = content.u_plus
    print(f"wrote {plot_S(content.problem, args.out, marks)}")
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("plot", help="figures of S and of the sector law (PNG or SVG)")
    which = p.add_subparsers(dest="figure", required=True)
    cradle = which.add_parser("cradle", help="S of the 3-ball cradle with Moreau's half-line "
                                             "and the sector-law point")
    cradle.add_argument("--v", type=float, default=1.0, help="speed of the released ball")
    cradle.add_argument("--out", default="cradle.png", help="output .png or .svg")
    cradle.set_defaults(func=run_cradle)
    sectors = which.add_parser("sectors", help="the six cones of the 3-ball sector law")
    sectors.add_argument("--out", default="sectors.png", help="output .png or .svg")
    sectors.set_defaults(func=run_sectors)
    s = which.add_parser("S", help="S of a problem file with two independent contacts")
    s.add_argument("file", help="problem file (.json or .toml)")
    s.add_argument("--out", default="S.png", help="output .png or .svg")
    s.set_defaults(func=run_S)
