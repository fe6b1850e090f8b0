"""``impactqp solve FILE``: apply an impact law to a problem file and report the result.

The law and its coefficients come from the file unless ``--law`` / ``--eps`` / ``--e`` /
``--E`` / ``--mu`` say otherwise. Without any, Moreau's law with ε = 0 is used
(docs/theory.md §3), or Coulomb's law for frictional contacts (docs/theory.md §16), whose μ
the file or ``--mu`` must give.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from ...errors import InputError
from ...io.file_laws import COEFFICIENT_KEYS, KNOWN_COEFFICIENTS, LAWS
from ...io.files import ProblemFile, load_problem
from ...laws.catalogue import NAMED_LAWS, law_named
from ...laws.friction import FRICTION_BACKENDS
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


def check_fit(law: str, contact_dim: int, file: str, source: str) -> None:
    """InputError, in the command line's words, when ``law`` (from ``source``: ``--law`` or
    the file) does not act on the file's contacts: a frictional law on frictionless contacts
    or a frictionless one on frictional contacts (docs/theory.md §16)."""
    frictional = [name for name, cls in NAMED_LAWS.items() if cls.frictional]
    if NAMED_LAWS[law].frictional and contact_dim == 1:
        raise InputError(f"{source} {law} needs frictional contacts, but {file} has "
                         "frictionless contacts (no contact_dim, or contact_dim = 1): pass "
                         "--law newton --e E (or another frictionless law), or give the file "
                         "contact_dim = 2 or 3 with that many columns of W per contact")
    if not NAMED_LAWS[law].frictional and contact_dim > 1:
        raise InputError(f"{source} {law} acts on frictionless contacts, but {file} has "
                         f"frictional contacts (contact_dim = {contact_dim}): pass --law "
                         f"{frictional[0]} --mu MU (and --e E for restitution), or give the "
                         "file contact_dim = 1 with the normal columns of W only")


def choose_law(args: argparse.Namespace, content: ProblemFile) -> tuple[str, Any]:
    """The law and coefficients: command-line flags override the file (which may have none).
    A law of several coefficients (Coulomb's μ and e) takes each from its flag or else from
    the file; the first of its keys is required when the law needs coefficients."""
    frictional = content.problem.contact_dim > 1
    law = args.law or content.law or ("coulomb" if frictional else "moreau")
    check_fit(law, content.problem.contact_dim, args.file,
              "--law" if args.law else "the file's law")
    keys = COEFFICIENT_KEYS.get(law, ())
    flags = {key: getattr(args, key) for key in KNOWN_COEFFICIENTS}
    stray = [k for k, v in flags.items() if v is not None and k not in keys]
    if stray:
        uses = ", ".join(f"--{key} with {' or '.join(laws)}"
                         for key, laws in KNOWN_COEFFICIENTS.items())
        raise InputError(f"--{stray[0]} does not apply to law {law!r}; use {uses}")
    if not keys:
        return law, None
    in_file = content.coefficients if law == content.law else None
    if len(keys) == 1:
        in_file = (in_file,)
    elif in_file is None:
        in_file = (None,) * len(keys)
    values = tuple(value if flags[key] is None else parse_numbers(f"--{key}", flags[key])
                   for key, value in zip(keys, in_file, strict=True))
    if values[0] is None and NAMED_LAWS[law].needs_coefficients:
        raise InputError(f"law {law!r} needs its coefficients: put {keys[0]!r} in the file or "
                         f"pass --{keys[0]}")
    if len(keys) == 1:
        return law, values[0]
    return law, None if all(v is None for v in values) else values


def solve_law(problem: ImpactProblem, law: str, coefficients: Any,
              backend: str = "auto") -> ImpactResult:
    """Apply the law called ``law`` (docs/theory.md §3, §6, §10, §16) through
    :func:`impactqp.solve`, with exactly its checks (a closed-form law refuses a named
    backend, as in Python, here in the command line's words); for Coulomb's law ``backend``
    is a friction method of the registry (:data:`~impactqp.laws.friction.FRICTION_BACKENDS`),
    as for :func:`impactqp.solve`."""
    impact_law = law_named(law, coefficients)
    if not impact_law.forms and backend not in ("auto", impact_law.closed_form_backend):
        raise InputError(f"--law {law} is evaluated in closed form: drop --backend {backend} "
                         "(or pass --backend auto)")
    return solve(problem, impact_law, backend)


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


def add_law_arguments(p: argparse.ArgumentParser) -> None:
    """The flags that choose the law and its coefficients (read by :func:`choose_law`):
    ``solve`` and ``bench`` take the same."""
    p.add_argument("--law", choices=LAWS, help="impact law (default: the file's, else moreau, "
                                               "or coulomb for frictional contacts)")
    p.add_argument("--eps", help="Moreau's restitution ε in [0, 1]")
    p.add_argument("--e", help="Newton's coefficients (newton, and the normal restitution of "
                               "coulomb, default 0; the energetic restitution of lzb, "
                               "default 1): one number or one per contact, e.g. 0.5,0.8")
    p.add_argument("--E", help="Frémond's matrix, rows separated by ';', e.g. '0.5,0;0,0.5'")
    p.add_argument("--mu", help="Coulomb's friction coefficients ≥ 0: one number or one per "
                                "contact, e.g. 0.3")
    p.add_argument("--stiffness", help="the LZB model's contact stiffnesses K > 0 (lzb, "
                                       "required): one number or one per contact, e.g. 1e7")
    p.add_argument("--exponent", help="the LZB model's force exponents η in [1, 3] (lzb, "
                                      "default 1.5, Hertz)")


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("solve", help="apply an impact law to a problem file (.json/.toml)")
    p.add_argument("file", help="problem file (.json or .toml)")
    add_law_arguments(p)
    p.add_argument("--backend", default="auto",
                   help="backend of the registry (default auto): a "
                        "QP backend, or for coulomb a friction method: "
                        f"{', '.join(FRICTION_BACKENDS)}")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(func=run)
