"""``impactqp fclib FILE``: solve a frictional contact problem (docs/theory.md §15) of an FCLib
HDF5 file or a Siconos text file (``.dat``, ``.dat.gz``; :func:`~impactqp.load_fclib` tells
them apart by content) with :func:`~impactqp.solve_friction` and print its certificate.

Exit status 0 on a certified answer, 2 otherwise (an unreadable or malformed file, a bad
option, no method certified at ``--tol``).
"""

from __future__ import annotations

import argparse
from typing import Any

from ...base.checks import FRICTION_TOL
from ...io.fclib import load_fclib
from ...laws.friction import FRICTION_BACKENDS, FrictionResult, solve_friction
from ...model.friction import FrictionContactProblem
from ..progress import progress
from ..report import to_json


def friction_report(problem: FrictionContactProblem, result: FrictionResult,
                    source: str) -> dict[str, Any]:
    """The figures of a certified answer: the problem's size, the method, the time and every
    residual of the certificate, in contact units, accepted (``natural_map`` is ABH's error,
    ``velocity``, ``cone``, ``dual_cone``, ``complementarity``) and reported
    (``siconos_error``, ``penetration``)."""
    cert = result.certificate
    return {"source": source, "contacts": problem.n_contacts,
            "contact_dim": problem.contact_dim, "method": result.backend,
            "iterations": result.iterations, "solve_time": result.solve_time,
            "certificate": {"ok": cert.ok, "tolerance": cert.tol, **cert.values,
                            **cert.reported}}


def format_friction(report: dict[str, Any]) -> str:
    """Plain text of :func:`friction_report`."""
    cert = report["certificate"]
    return "\n".join([
        f"{report['source']}: {report['contacts']} contacts, d = {report['contact_dim']}",
        f"method     {report['method']}, {report['iterations']} iterations, "
        f"{report['solve_time']:.3g} s",
        f"certificate: {'ok' if cert['ok'] else 'FAILED'} (tol {cert['tolerance']:.0e})",
        f"  natural map ‖F‖/‖q‖ (ABH)      {cert['natural_map']:.3e}",
        f"  Siconos ‖F‖/max(‖q‖,‖r‖,‖u‖)    {cert['siconos_error']:.3e}",
        f"  cone r ∈ K_μ                   {cert['cone']:.3e}",
        f"  dual ũ ∈ K_1/μ                 {cert['dual_cone']:.3e}",
        f"  complementarity r_c·ũ_c = 0    {cert['complementarity']:.3e}",
        f"  velocity ‖u − (Wr + q)‖/‖q‖    {cert['velocity']:.3e}",
        f"  penetration ‖(−u_n)₊‖/‖q‖      {cert['penetration']:.3e}",
    ])


def run(args: argparse.Namespace) -> int:
    problem = load_fclib(args.file)
    with progress(f"solving the frictional contact problem ({problem.n_contacts} contacts)"):
        result = solve_friction(problem, backend=args.backend, tol=args.tol)
    report = friction_report(problem, result, str(args.file))
    print(to_json(report) if args.json else format_friction(report))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("fclib", help="solve a frictional contact problem (FCLib .hdf5 or "
                                     "Siconos .dat/.dat.gz) with a certificate")
    p.add_argument("file", help="FCLib problem file (.hdf5, local or global) or Siconos text "
                                "file (.dat, .dat.gz)")
    p.add_argument("--backend", default="auto", choices=FRICTION_BACKENDS,
                   help="method of solve_friction (default auto)")
    p.add_argument("--tol", type=float, default=FRICTION_TOL,
                   help="tolerance of the certificate, ‖F‖/‖q‖ among others (default "
                        f"{FRICTION_TOL:g})")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(func=run)
