"""``impactqp plot cradle|sectors|S FILE``: the figures of docs/theory.md §5, §6 and §10 as PNG,
SVG or PDF (chosen by the suffix of ``--out``), drawn by the functions of Python
(:func:`impactqp.plot_admissible`, :func:`impactqp.plot_sectors`) for any number of contacts
or balls.

Without ``--out`` a figure is written to ``cradle.png``, ``sectors.png`` or ``S.png`` in the
current directory. An existing file is never overwritten unless ``--force`` is given.

Needs the optional extra ``plot`` (matplotlib).
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ...errors import InputError
from ...io.files import load_problem


def _target(args: argparse.Namespace) -> Path:
    """The output path, refused when it exists and ``--force`` was not given."""
    out = Path(args.out)
    if out.exists() and not args.force:
        raise InputError(f"{out} exists; pass --force to overwrite it or --out to write "
                         "elsewhere")
    return out


def run_cradle(args: argparse.Namespace) -> int:
    from ...base.figure import figure_format
    from ...figures.sections import plot_cradle

    figure_format(args.out)
    print(f"wrote {plot_cradle(_target(args), v=args.v)}")
    return 0


def run_sectors(args: argparse.Namespace) -> int:
    from ...base.figure import figure_format
    from ...figures.sections import plot_sectors

    figure_format(args.out)
    out = _target(args)
    if args.file is not None:
        if args.masses is not None or args.balls is not None:
            raise InputError("give a problem FILE or --balls/--masses, not both")
        plot_sectors(load_problem(args.file).problem, out)
    else:
        plot_sectors(path=out, n_balls=3 if args.balls is None else args.balls,
                     masses=args.masses)
    print(f"wrote {out}")
    return 0


def run_S(args: argparse.Namespace) -> int:
    from ...base.figure import figure_format
    from ...figures.sections import plot_admissible
    from .solve import solve_law

    figure_format(args.out)
    out = _target(args)
    content = load_problem(args.file)
    if content.problem.contact_dim > 1:
        raise InputError(f"plot S draws S of frictionless contacts; {args.file} is "
                         f"frictional (contact_dim = {content.problem.contact_dim}): give "
                         "plot S a file with contact_dim = 1 and the normal columns of W "
                         "only")
    marks = {}
    if content.law is not None:
        result = solve_law(content.problem, content.law, content.coefficients)
        marks[f"{content.law} law u⁺"] = result.u_plus
    if content.u_plus is not None:
        marks["u_plus of the file"] = content.u_plus
    plot_admissible(content.problem, out, candidates=marks)
    print(f"wrote {out}")
    return 0


def _output_options(parser: argparse.ArgumentParser, default: str) -> None:
    parser.add_argument("--out", default=default,
                        help=f"output file, .png, .svg or .pdf (default: ./{default})")
    parser.add_argument("--force", action="store_true",
                        help="overwrite the output file if it exists (default: refuse)")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("plot", help="figures of S and of the sector law (PNG, SVG or PDF)")
    which = p.add_subparsers(dest="figure", required=True)
    cradle = which.add_parser("cradle", help="S of the 3-ball cradle with Moreau's half-line "
                                             "and the sector-law point")
    cradle.add_argument("--v", type=float, default=1.0, help="speed of the released ball")
    _output_options(cradle, "cradle.png")
    cradle.set_defaults(func=run_cradle)
    sectors = which.add_parser("sectors", help="the cones of the sector law (equal balls) or "
                                               "of the reflection law (masses at angles "
                                               "180°/k), cut by a plane of γ⁻")
    sectors.add_argument("file", nargs="?", default=None,
                         help="a chain's problem file (.json or .toml): its masses and its "
                              "γ⁻ (default: equal balls)")
    sectors.add_argument("--balls", type=int, default=None,
                         help="number of equal balls, at least 3 (default 3)")
    sectors.add_argument("--masses", type=float, nargs="+", default=None,
                         help="the balls' masses (a free chain), e.g. --masses 1 0.4142 1")
    _output_options(sectors, "sectors.png")
    sectors.set_defaults(func=run_sectors)
    s = which.add_parser("S", help="S of a problem file, cut by a plane through u⁻ (any "
                                   "number of contacts), with the laws' u⁺ marked")
    s.add_argument("file", help="problem file (.json or .toml)")
    _output_options(s, "S.png")
    s.set_defaults(func=run_S)
