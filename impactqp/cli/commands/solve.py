"""``impactqp solve FILE``: apply an impact law to a problem file and report the result.

The law and its coefficients come from the file unless ``--law`` / ``--eps`` / ``--e`` /
``--E`` say otherwise. Without any, Moreau's law with ε = 0 is used (docs/theory.md §3).
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from ...errors import InputError
from ...io.files import COEFFICIENT_KEYS, LAWS, ProblemFile, load_problem
from ...laws.catalogue import NAMED_LAWS, law_named
from ...laws.pipeline import solve
from ...laws.result import ImpactResult
from ...model.problem import ImpactProblem
from ..progress import progress
from ..report import format_solution, solution_report, to_json


def parse_numbers(flag: str, text: str) -> float | np.ndarray:
    """``"0.5"`` → scalar, ``"0.1,0.2"`` → vector, ``"0.1,0;0,0.2"`` → matrix (rows by ';')."""
    try:
        rows = [[float(x) for x in row.split(",")] for row in text.split(";")]
    except ValueError:
        raise InputError(f"{flag} must be numbers separated by ',' (rows by ';'), "
                         f"got {text!r}") from None
    if ";" not in text:
        return np.array(rows[0]) if "," in text else rows[0][0]
    if len({len(r) for r in rows}) > 1:
        raise InputError(f"{flag} is ragged: its rows have different lengths in {text!r}")
    return np.array(rows)


def choose_law(args: argparse.Namespace, content: ProblemFile) -> tuple[str, Any]:
    """The law and coefficients: command-line flags override the file (which may have none)."""
    law = args.law or content.law or "moreau"
    flags = {"eps": args.eps, "e": args.e, "E": args.E}
    given = [k for k, v in flags.items() if v is not None]
    wanted = COEFFICIENT_KEYS.get(law)
    if any(k != wanted for k in given):
        uses = ", ".join(f"--{key} with {name}" for name, key in COEFFICIENT_KEYS.items())
        raise InputError(f"--{given[0]} does not apply to law {law!r}; use {uses}")
    if given:
        return law, parse_numbers(f"--{wanted}", flags[wanted])
    coefficients = content.coefficients if law == content.law else None
    if coefficients is None and NAMED_LAWS[law].needs_coefficients:
        raise InputError(f"law {law!r} needs its coefficients: put {wanted!r} in the file or "
                         f"pass --{wanted}")
    return law, coefficients


def solve_law(problem: ImpactProblem, law: str, coefficients: Any,
              backend: str = "auto") -> ImpactResult:
    """Apply the law called ``law`` (docs/theory.md §3, §6, §10) through :func:`impactqp.solve`,
    with exactly its checks (a closed-form law refuses a named backend, as in Python)."""
    return solve(problem, law_named(law, coefficients), backend)


def run(args: argparse.Namespace) -> int:
    content = load_problem(args.file)
    law, coefficients = choose_law(args, content)
    n = content.problem.n_dof
    with progress(f"solving with law {law} (n = {n})"):
        result = solve_law(content.problem, law, coefficients, args.backend)
    with progress(f"checking u⁺ ∈ S and classifying it (n = {n})"):
        report = solution_report(result, str(args.file))
    print(to_json(report) if args.json else format_solution(report))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("solve", help="apply an impact law to a problem file (.json/.toml)")
    p.add_argument("file", help="problem file (.json or .toml)")
    p.add_argument("--law", choices=LAWS, help="impact law (default: the file's, else moreau)")
    p.add_argument("--eps", help="Moreau's restitution ε in [0, 1]")
    p.add_argument("--e", help="Newton's coefficients: one number or one per contact, e.g. 0.5,0.8")
    p.add_argument("--E", help="Frémond's matrix, rows separated by ';', e.g. '0.5,0;0,0.5'")
    p.add_argument("--backend", default="auto", help="QP backend (default auto)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(func=run)
