"""The suite's rows that are runs rather than single solves: simulations beside Siconos,
per-impact timings of impactqp alone, and the first calls of a fresh process.

- ``sim-ball`` (size: steps), ``sim-cradle``, ``sim-column`` (size: balls): ``iq.simulate``
  (Moreau–Jean) and Siconos' MoreauJeanOSI on the same system (:mod:`.simulation`), run
  interleaved; times are seconds per whole run, "error" is the agreement of the two (largest
  |Δq| or |Δv|).
- ``event-ball`` (size: simulated seconds): the event-driven bouncing ball; times are
  seconds per impact (run time / impacts).
- ``lzb``: one LZB impact of a steel chain (as Siconos' ChainOfBalls example); times are
  seconds per impact, the status is the LZB certificate's verdict.
- ``startup``: a fresh interpreter's first calls (numba's cache as the environment has it,
  filled by a first process), seconds beyond the same calls warm (:mod:`.startup`).
"""

from __future__ import annotations

import statistics
import time
from typing import Any

import impactqp as iq
from impactqp.laws.lzb import LZB

from . import simulation, startup
from .measure import ACCURATE, quiet_stdout, row

#: per suite: (system, balls, steps) compared with Siconos, and the interleaved repeats
SIMULATIONS: dict[str, tuple[list[tuple[str, int, int]], int]] = {
    "quick": ([("ball", 1, 200), ("cradle", 3, 600), ("column", 10, 100)], 1),
    "full": ([("ball", 1, 2000), ("cradle", 5, 1000), ("column", 100, 1000)], 5),
}
#: per suite: event-driven ball's end time, LZB chain sizes, and (most repeats, seconds)
PER_IMPACT: dict[str, tuple[float, list[int], tuple[int, float]]] = {
    "quick": (2.0, [10], (1, 0.0)),
    "full": (10.0, [10, 100], (5, 10.0)),
}
#: suites that measure the first calls of a fresh process (a few seconds of subprocesses)
STARTUP = ("full",)
#: the trajectories of Siconos' BouncingBallTS and of impactqp agree to round-off
BALL_AGREEMENT = 1e-12
SIM_NOTE = {
    "iq:simulate": "iq.simulate(system, iq.Newton(e), T, h=h, theta=0.5, keep_events=False) "
                   "per run; error = largest |Δq|, |Δv| against Siconos",
    "siconos:MoreauJeanOSI": "computeOneStep/nextStep loop (LCP, Lemke), model built "
                             "before, in /usr/bin/python3; run interleaved with impactqp",
}
SIM_FAMILY = {"ball": "sim-ball", "cradle": "sim-cradle", "column": "sim-column"}


def _repeat(run: Any, repeats: int, budget: float) -> list[Any]:
    """``run()`` once untimed, then up to ``repeats`` times or until ``budget`` seconds."""
    run()
    out: list[Any] = []
    start = time.perf_counter()
    while len(out) < repeats and (not out or time.perf_counter() - start < budget):
        out.append(run())
    return out


def run_simulations(suite: str, python: str = simulation.SICONOS_PYTHON) -> list[dict]:
    """Rows of the three systems, impactqp and Siconos interleaved (Siconos skipped when
    ``python`` cannot import it)."""
    if suite not in SIMULATIONS:
        return []
    systems, repeats = SIMULATIONS[suite]
    where, why = simulation.siconos_available(python)
    server = simulation.SiconosServer(where) if where else None
    rows: list[dict] = []
    try:
        for system, n, steps in systems:
            family = SIM_FAMILY[system]
            size = steps if system == "ball" else n
            try:
                with quiet_stdout():
                    out = simulation.compare(system, n, steps, repeats, server)
            except Exception as exc:  # a failing run is a result
                msg = f"{type(exc).__name__}: {exc}"
                rows += [row(family, size, m, g, status="failed", message=msg, note=SIM_NOTE[m])
                         for m, g in (("iq:simulate", "impactqp"),
                                      ("siconos:MoreauJeanOSI", "peer"))]
                continue
            agree = out["agreement"]
            ok = agree is None or agree <= ACCURATE
            where_from = f"Siconos MoreauJeanOSI, {steps} steps"
            rows.append(row(family, size, "iq:simulate", "impactqp",
                            status="ok" if ok else "inaccurate", times=out["impactqp"],
                            error=agree, reference=where_from, note=SIM_NOTE["iq:simulate"],
                            message="" if ok else f"differs from Siconos by {agree:.1e}"))
            if out["siconos"]:
                rows.append(row(family, size, "siconos:MoreauJeanOSI", "peer",
                                status="ok" if ok else "inaccurate", times=out["siconos"],
                                error=agree, reference=where_from,
                                note=SIM_NOTE["siconos:MoreauJeanOSI"]))
            else:
                rows.append(row(family, size, "siconos:MoreauJeanOSI", "peer",
                                status="failed" if out["error"] else "skipped",
                                message=out["error"] or f"siconos not importable: {why}",
                                reference=where_from, note=SIM_NOTE["siconos:MoreauJeanOSI"]))
    finally:
        if server is not None:
            server.close()
    return rows


def event_ball_run(t_end: float) -> tuple[float, int]:
    """Seconds of the event-driven bouncing ball (Newton e = 0.9, output every 10 ms) and
    its number of impacts."""
    system = simulation.impactqp_model("ball", 1)
    start = time.perf_counter()
    tr = iq.simulate(system, iq.Newton(0.9), t_end, scheme="event-driven", h=0.01)
    seconds = time.perf_counter() - start
    if not tr.events or not tr.certified:
        raise RuntimeError("the event-driven ball had no certified impact")
    return seconds, len(tr.events)


def lzb_run(n: int) -> tuple[float, float, int, bool]:
    """Seconds of one LZB impact of ``n`` steel balls (radius 1 cm, Siconos' ChainOfBalls
    material: 7780 kg/m³, E = 203 GPa, ν = 0.3, Hertz 3/2, e = 1, striker at 1 m/s), its
    CPU seconds (which another process sharing the cores inflates less), the integration's
    steps and its certificate's verdict."""
    chain = iq.chains.monodisperse_chain(n, 0.01, density=7780, young=203e9, poisson=0.3)
    law = LZB(chain.stiffness, exponent=1.5, restitution=1.0)
    start, cpu = time.perf_counter(), time.process_time()
    result = iq.solve(chain.problem, law)
    seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    return seconds, cpu, result.certificate.record.steps, bool(result.certificate.ok)


def run_per_impact(suite: str) -> list[dict]:
    """Rows of the event-driven ball and the LZB chains: seconds per impact."""
    if suite not in PER_IMPACT:
        return []
    t_end, sizes, (repeats, budget) = PER_IMPACT[suite]
    rows = []
    note = f"iq.simulate(ball, iq.Newton(0.9), {t_end:g}, scheme='event-driven', h=0.01); " \
           "time per impact = run time / impacts"
    try:
        runs = _repeat(lambda: event_ball_run(t_end), repeats, budget)
        impacts = runs[0][1]
        rows.append(row("event-ball", t_end, "iq:event-driven", "impactqp", status="ok",
                        times=[s / k for s, k in runs], note=note,
                        reference=f"{impacts} certified impacts in {t_end:g} s"))
    except Exception as exc:
        rows.append(row("event-ball", t_end, "iq:event-driven", "impactqp", status="failed",
                        message=f"{type(exc).__name__}: {exc}", note=note))
    note = "iq.solve(chain.problem, LZB(stiffness, 1.5, 1.0)) of monodisperse_chain(N): " \
           "one impact"
    for n in sizes:
        try:
            runs = _repeat(lambda n=n: lzb_run(n), repeats, budget)
            ok = all(verdict for *_, verdict in runs)
            cpu = statistics.median(c for _, c, _, _ in runs)
            rows.append(row("lzb", n, "iq:lzb", "impactqp", status="ok" if ok else "failed",
                            message="" if ok else "LZB certificate failed",
                            times=[s for s, *_ in runs], note=note,
                            reference=f"LZB certificate; CPU {cpu * 1e3:.1f} ms (median), "
                                      f"{runs[0][2]} DOP853 steps"))
        except Exception as exc:
            rows.append(row("lzb", n, "iq:lzb", "impactqp", status="failed",
                            message=f"{type(exc).__name__}: {exc}", note=note))
    return rows


def run_startup(suite: str) -> list[dict]:
    """The first calls of a fresh process beyond the same calls warm (full suite only)."""
    if suite not in STARTUP:
        return []
    note = ("fresh interpreter: import impactqp, then 3-ball cradle, dense m = 10, 10⁴-ball "
            "chain, batch of 10³; seconds of the first calls beyond the second ones")
    try:
        startup.probe()  # fills numba's cache if this checkout has not yet
        runs = [startup.probe() for _ in range(3)]
    except Exception as exc:
        return [row("startup", 4, "iq:first calls", "impactqp", status="failed",
                    message=f"{type(exc).__name__}: {exc}", note=note)]
    median = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
    detail = ", ".join(f"{k} {v * 1e3:.1f} ms" for k, v in median.items()
                       if "warm" not in k)
    rows = [row("startup", 4, "iq:first calls", "impactqp", status="ok",
                times=[startup.first_call_extra(r) for r in runs],
                reference=f"medians of 3 processes: {detail}", note=note)]
    return rows + run_first_hour()


FIRST_HOUR = {"demo: first line": 2.0, "demo": 10.0, "first frictional impact (process)": 10.0,
              "impactqp compile": 60.0}
"""Issue 27's targets, seconds from an empty cache with impactqp's defaults."""


def run_first_hour() -> list[dict]:
    """A new user's first commands from an empty cache (:func:`.startup.first_hour`), one
    row each, with its target."""
    note = "fresh process, empty numba cache, impactqp's defaults; target in the reference"
    try:
        runs = [startup.first_hour(compile_all=i == 0) for i in range(3)]
    except Exception as exc:
        return [row("first hour", 1, "iq:first hour", "impactqp", status="failed",
                    message=f"{type(exc).__name__}: {exc}", note=note)]
    return [row("first hour", 1, f"iq:{key}", "impactqp", status="ok",
                times=[r[key] for r in runs if key in r], note=note,
                reference=f"target ≤ {target:g} s")
            for key, target in FIRST_HOUR.items()]
