"""The friction problems a solve should end in microseconds: impactqp's default beside Siconos'
NSGS in one run (issue 28's targets: ≤ NSGS + 10 µs on 1–9 contacts, ≤ 1× NSGS from 5
contacts on).

``python -m benchmarks.friction_tiny [--rounds N] [--out DIR]`` times
``iq.solve_friction(problem, tol=1e-8)`` and Siconos 4.4's NSGS (fc3d/fc2d driver, served in
Debian's Python by :mod:`benchmarks.siconos_worker`) on the problems of the widened FCLib set
with at most :data:`MOST_CONTACTS` contacts and on those NSGS ends in one sweep
(:data:`ONE_SWEEP`), in alternating rounds (impactqp, then Siconos, ``--rounds`` times), and
reports per problem the median over the rounds of each side's median time, the difference
and the ratio, and the verdict against the targets. Both answers are judged by
:func:`impactqp.model.friction.certify_friction` at 1e-8, as in :mod:`benchmarks.friction`.
With ``--out`` it writes ``summary.md`` and ``results.json`` there.
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import impactqp as iq
from impactqp.model.friction import FrictionContactProblem, certify_friction

from . import friction_data
from .friction import TOL, SiconosPeer, _repeat, warm_up
from .friction_data import FrictionCase
from .simulation import SICONOS_PYTHON

MOST_CONTACTS = 9
"""The tiny problems: at most this many contacts."""
TINY = ("CubeH8", "FC3D-1c", "FC3D-RR-1c", "Rover11035", "Rover11211", "FC2D-SliderCrank-0",
        "FC2D-SliderCrank-1", "Rover4396", "FC3D-Example1", "TwoRods1-condensed",
        "Confeti-ex13-4c", "Rover1039", "Rover4144", "Rover1040", "Rover9770", "FC2D-00394",
        "LMGC-00046", "NESpheres-10")
"""The problems of the widened set (:data:`benchmarks.friction_data.ALL`) with at most
:data:`MOST_CONTACTS` contacts."""
ONE_SWEEP = ("FC2D-00031", "FC2D-00374", "NESpheres-30")
"""Larger problems of the widened set Siconos' NSGS ends in one sweep."""
BUDGET, REPEATS = 0.05, 2000
"""Seconds and most runs of one side's timed repeats in one round."""
FIRST_SOLVES = 200
"""First solves of fresh problem copies timed per round."""
SLACK = 10e-6
"""The allowance below :data:`FIVE` contacts: impactqp ≤ NSGS + 10 µs."""
FIVE = 5
"""From this many contacts on, the target is ≤ 1× NSGS."""


def cases() -> list[FrictionCase]:
    """The problems timed, by contacts then name.

    Raises
    ------
    ValueError
        A problem of :data:`TINY` has more than :data:`MOST_CONTACTS` contacts.
    """
    loaded = [friction_data.load(name) for name in (*TINY, *ONE_SWEEP)]
    for case in loaded:
        if case.name in TINY and case.n_contacts > MOST_CONTACTS:
            raise ValueError(f"{case.name} has {case.n_contacts} contacts, not a tiny problem")
    return sorted(loaded, key=lambda c: (c.n_contacts, c.name))


def meets(contacts: int, ours: float, nsgs: float) -> bool:
    """The target on a problem of ``contacts`` contacts, times in seconds: ≤ NSGS + 10 µs
    below :data:`FIVE` contacts, ≤ 1× NSGS from there on."""
    return ours <= (nsgs if contacts >= FIVE else nsgs + SLACK)


def fresh(problem: FrictionContactProblem) -> FrictionContactProblem:
    """A new problem object of the same W, q and μ (its own copies), never solved: what a
    simulator poses at each step."""
    return FrictionContactProblem(problem.W.copy(), problem.q.copy(), problem.mu,
                                  contact_dim=problem.contact_dim)


def first_solves(problem: FrictionContactProblem) -> list[float]:
    """The times of :data:`FIRST_SOLVES` first solves, each of a :func:`fresh` copy of
    ``problem`` made before its timer starts."""
    copies = [fresh(problem) for _ in range(FIRST_SOLVES)]
    times = []
    for copy in copies:
        t0 = time.perf_counter()
        iq.solve_friction(copy, tol=TOL)
        times.append(time.perf_counter() - t0)
    return times


def measure(case: FrictionCase, peer: SiconosPeer, rounds: int) -> dict[str, Any]:
    """impactqp's and NSGS's times on ``case`` in ``rounds`` alternating rounds: impactqp's
    solves of the one problem object (from the second on, of the problem it keeps packed),
    and its first solves of fresh copies."""
    problem = case.problem
    ours: list[float] = []
    firsts: list[float] = []
    theirs: list[float] = []
    result = iq.solve_friction(problem, tol=TOL)
    nsgs: dict = {}
    for _ in range(rounds):
        ours.append(statistics.median(_repeat(lambda: iq.solve_friction(problem, tol=TOL),
                                              BUDGET, REPEATS)))
        firsts.append(statistics.median(first_solves(problem)))
        nsgs = peer.solve(case, "NSGS", budget=BUDGET, max_repeats=REPEATS)
        theirs.append(statistics.median(nsgs["times"]) if nsgs["times"] else float("nan"))
    cert = certify_friction(problem, result.r, result.u, tol=TOL)
    iq_time, nsgs_time = statistics.median(ours), statistics.median(theirs)
    return {"problem": case.name, "contacts": case.n_contacts, "d": problem.contact_dim,
            "iq_us": iq_time * 1e6, "nsgs_us": nsgs_time * 1e6,
            "first_us": statistics.median(firsts) * 1e6,
            "ratio": iq_time / nsgs_time, "minus_us": (iq_time - nsgs_time) * 1e6,
            "target": "≤ 1× NSGS" if case.n_contacts >= FIVE else "≤ NSGS + 10 µs",
            "met": meets(case.n_contacts, iq_time, nsgs_time), "backend": result.backend,
            "iq_error": cert.error, "iq_ok": cert.ok, "nsgs_status": nsgs["status"],
            "nsgs_error": nsgs["error"]}


def summary(rows: list[dict[str, Any]], rounds: int) -> str:
    """The markdown table of :func:`measure`'s rows."""
    lines = ["# Tiny friction problems: impactqp's default beside Siconos' NSGS", "",
             f"`python -m benchmarks.friction_tiny --rounds {rounds}`: per problem "
             f"{rounds} alternating rounds of timed repeats (≤ {BUDGET:g} s each side), the "
             "median of the rounds' medians; errors are ABH ‖F‖/‖q‖ recomputed by "
             "certify_friction. iq:auto solves one problem object again and again (from its "
             "second solve on, impactqp keeps it packed); *first solve* is the median of "
             f"{FIRST_SOLVES} first solves of fresh copies of the problem (what a simulator, "
             "posing a new problem at each step, pays), timed in the same rounds.", "",
             "| problem | contacts | d | iq:auto | first solve | siconos:NSGS | iq − NSGS | "
             "ratio | target | met | route |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(
            f"| {r['problem']} | {r['contacts']} | {r['d']} | {r['iq_us']:.1f} µs "
            f"({r['iq_error']:.0e}) | {r.get('first_us', math.nan):.1f} µs | "
            f"{r['nsgs_us']:.1f} µs ({r['nsgs_status']}) | "
            f"{r['minus_us']:+.1f} µs | {r['ratio']:.2f} | {r['target']} | "
            f"{'yes' if r['met'] else 'no'} | {r['backend']} |")
    met = sum(r["met"] for r in rows)
    ratios = [r["ratio"] for r in rows if r["ratio"] > 0.0]
    mean = math.exp(sum(math.log(x) for x in ratios) / len(ratios)) if ratios else math.nan
    lines += ["", f"Targets met on {met} of {len(rows)} problems; geometric mean of the "
              f"ratios {mean:.2f}."]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Run the comparison; print the table (and write it with ``--out``)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks.friction_tiny")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--siconos-python", default=SICONOS_PYTHON)
    parser.add_argument("--only", nargs="*", default=None, help="problem names")
    args = parser.parse_args(argv)
    warm_up()
    chosen = cases()
    if args.only:
        chosen = [c for c in chosen if c.name in args.only]
    peer = SiconosPeer(args.siconos_python)
    try:
        rows = [measure(case, peer, args.rounds) for case in chosen]
    finally:
        peer.close()
    text = summary(rows, args.rounds)
    print(text)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "summary.md").write_text(text)
        (args.out / "results.json").write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
