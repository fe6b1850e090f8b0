"""``impactqp bench FILE``: every backend on the impact of a problem file — time, error
against the best certified answer, the certificate's verdict and why a backend was refused
(:func:`impactqp.compare_backends`).

The law and its coefficients come from the file unless ``--law`` / ``--eps`` / ``--e`` /
``--E`` / ``--mu`` say otherwise, exactly as for ``impactqp solve``.
"""

from __future__ import annotations

import argparse

from ...base.checks import DEFAULT_TOL
from ...io.files import load_problem
from ...laws.catalogue import law_named
from ...verification.bench import compare_backends
from ..progress import progress
from ..report import to_json
from .solve import add_law_arguments, choose_law


def run(args: argparse.Namespace) -> int:
    content = load_problem(args.file)
    name, coefficients = choose_law(args, content)
    law = law_named(name, coefficients)
    names = None if args.backends is None else \
        [b.strip() for b in args.backends.split(",") if b.strip()]
    with progress(f"comparing backends with law {name} (n = {content.problem.n_dof})"):
        table = compare_backends(content.problem, law, names, repeats=args.repeats,
                                 tol=args.tol)  # -v/-vv: the log that main() switches on
    if args.json:
        print(to_json({"file": str(args.file), "law": name, "best": table.best,
                       "tol": table.tol, "repeats": table.repeats, "rows": table.to_rows()}))
    else:
        print(table)
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="compare every backend on a problem file (.json/.toml)")
    p.add_argument("file", help="problem file (.json or .toml)")
    add_law_arguments(p)
    p.add_argument("--backends", help="comma-separated backends to compare, e.g. "
                                      "'exact,clarabel,cvxpy:SCS' (default: every backend "
                                      "that serves the law; `impactqp backends` lists them)")
    p.add_argument("--repeats", type=int, default=3,
                   help="timed calls per backend after a first untimed one (default 3); the "
                        "table shows their median")
    p.add_argument("--tol", type=float, default=DEFAULT_TOL,
                   help=f"certificate tolerance (default {DEFAULT_TOL:g})")
    p.add_argument("--json", action="store_true", help="print the table as JSON rows")
    p.set_defaults(func=run)
