"""``impactqp bench FILE``: every backend on the problem of a file — time, error against the
best certified answer, the certificate's verdict and why a backend was refused
(:func:`impactqp.compare_backends`).

A problem file (``.json``, ``.toml``) holds an impact: its law and coefficients come from the
file unless ``--law`` / ``--eps`` / ``--e`` / ``--E`` / ``--mu`` say otherwise, exactly as for
``impactqp solve``. Any other file is read as a frictional contact problem, an FCLib file
(``.hdf5``) or a Siconos text file (``.dat``, ``.dat.gz``; :func:`impactqp.load_fclib` tells
them apart by content): its μ is its law, so the friction methods are compared
(:func:`impactqp.solve_friction`) and the law flags are refused.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ...base.checks import DEFAULT_TOL, FRICTION_TOL
from ...errors import InputError
from ...io.fclib import load_fclib
from ...io.file_laws import KNOWN_COEFFICIENTS
from ...io.files import FORMATS, load_problem
from ...laws.catalogue import law_named
from ...verification.bench import BackendComparison, compare_backends
from ..progress import progress
from ..report import to_json
from .solve import add_law_arguments, choose_law


def run(args: argparse.Namespace) -> int:
    names = None if args.backends is None else \
        [b.strip() for b in args.backends.split(",") if b.strip()]
    if Path(args.file).suffix.lower() in FORMATS:
        law, table = _impact(args, names)
    else:
        law, table = "coulomb (the file's μ)", _friction(args, names)
    if args.json:
        print(to_json({"file": str(args.file), "law": law, "best": table.best,
                       "tol": table.tol, "repeats": table.repeats, "rows": table.to_rows()}))
    else:
        print(table)
    return 0


def _impact(args: argparse.Namespace, names: list[str] | None) -> tuple[str,
                                                                          BackendComparison]:
    """The law's name and the comparison on a problem file's impact."""
    content = load_problem(args.file)
    name, coefficients = choose_law(args, content)
    law = law_named(name, coefficients)
    with progress(f"comparing backends with law {name} (n = {content.problem.n_dof})"):
        return name, compare_backends(content.problem, law, names, repeats=args.repeats,
                                      tol=args.tol)


def _friction(args: argparse.Namespace, names: list[str] | None) -> BackendComparison:
    """The comparison of the friction methods on an FCLib or Siconos file's problem."""
    given = [f"--{flag}" for flag in ("law", *KNOWN_COEFFICIENTS)
             if getattr(args, flag) is not None]
    if given:
        raise InputError(f"{given[0]} does not apply to {args.file}: a frictional contact "
                         "problem (FCLib or Siconos file) carries its law, Coulomb's with its "
                         "μ; drop the flag")
    problem = load_fclib(args.file)
    with progress(f"comparing friction methods ({problem.n_contacts} contacts)"):
        return compare_backends(problem, backends=names, repeats=args.repeats, tol=args.tol)


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="compare every backend on a problem file (.json/.toml) "
                                     "or every friction method on an FCLib/Siconos file")
    p.add_argument("file", help="problem file (.json or .toml), or a frictional contact "
                                "problem: FCLib (.hdf5) or Siconos text (.dat, .dat.gz)")
    add_law_arguments(p)
    p.add_argument("--backends", help="comma-separated backends to compare, e.g. "
                                      "'exact,clarabel,cvxpy:SCS' or 'auto,nsgs' (default: "
                                      "every backend that serves the law, every friction "
                                      "method for FCLib/Siconos files; `impactqp backends` "
                                      "lists them)")
    p.add_argument("--repeats", type=int, default=3,
                   help="timed calls per backend after two untimed ones (default 3); the "
                        "table shows their median")
    p.add_argument("--tol", type=float, default=None,
                   help=f"certificate tolerance (default {DEFAULT_TOL:g} for an impact, "
                        f"{FRICTION_TOL:g} for a frictional contact problem)")
    p.add_argument("--json", action="store_true", help="print the table as JSON rows")
    p.set_defaults(func=run)
