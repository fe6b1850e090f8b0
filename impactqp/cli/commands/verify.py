"""``impactqp verify FILE``: is a candidate post-impact velocity admissible (u⁺ ∈ S,
docs/theory.md §2, §16: with the friction cones of μ for frictional contacts)?

Exit status: 0 admissible, 1 not admissible, 2 bad input.
"""

from __future__ import annotations

import argparse

from ...base.arrays import as_vector
from ...errors import InputError
from ...io.files import ProblemFile, load_problem
from ...model.admissible import AdmissibleSet
from ..progress import progress
from ..report import format_verdict, membership_report, to_json
from .solve import parse_numbers


def admissible_set(content: ProblemFile, mu_flag: str | None) -> AdmissibleSet:
    """S of the file's problem; for frictional contacts with μ from ``--mu`` or else from the
    file's Coulomb law (docs/theory.md §16)."""
    problem = content.problem
    if problem.contact_dim == 1:
        if mu_flag is not None:
            raise InputError("--mu applies to frictional contacts (contact_dim 2 or 3); this "
                             "problem's contacts are frictionless")
        return problem.admissible_set()
    if mu_flag is not None:
        return problem.admissible_set(mu=parse_numbers("--mu", mu_flag))
    mu = content.coefficients[0] if isinstance(content.coefficients, tuple) else None
    if mu is None:
        raise InputError(f"{content.path}: S of frictional contacts depends on μ: pass --mu or "
                         "put law = 'coulomb' with mu in the file")
    return problem.admissible_set(mu=mu)


def run(args: argparse.Namespace) -> int:
    content = load_problem(args.file)
    if args.u_plus is not None:
        u_plus = as_vector("--u-plus", parse_numbers("--u-plus", args.u_plus),
                           content.problem.n_dof)
    elif content.u_plus is not None:
        u_plus = content.u_plus
    else:
        raise InputError(f"{args.file}: no candidate u⁺: pass --u-plus v1,v2,... or put "
                         "'u_plus' in the file")
    S = admissible_set(content, args.mu)
    with progress(f"checking u⁺ ∈ S, exactly and by the SOCP (n = {content.problem.n_dof})"):
        report = membership_report(content.problem, u_plus, S=S)
    print(to_json(report) if args.json else format_verdict(report, str(args.file)))
    return 0 if report["admissible"] else 1


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("verify", help="check a candidate u⁺ against S (exit 0 yes, 1 no, 2 bad "
                                      "input)")
    p.add_argument("file", help="problem file (.json or .toml)")
    p.add_argument("--u-plus", help="candidate u⁺ as v1,v2,... (default: the file's u_plus)")
    p.add_argument("--mu", help="friction coefficients of frictional contacts: one number or "
                                "one per contact (default: the file's coulomb mu)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(func=run)
