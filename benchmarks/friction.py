"""The friction suite: FCLib problems solved by impactqp and by Siconos' fc3d solvers.

Every answer, impactqp's or Siconos', is judged by the same figure recomputed here by
:func:`impactqp.model.friction.certify_friction` from (W, q, μ, r): the natural-map error
‖F‖/‖q‖ (ABH) at tolerance :data:`TOL`; Siconos' own error is recorded in the message
only. A solve that does not reach the tolerance is a failure whose time spent is kept
(it counts as ∞ in the Dolan–Moré profile, :mod:`benchmarks.perf_profile`), as is a run
stopped after :data:`TIME_LIMIT` seconds.

Rows: family ``friction:<problem>`` (size: contacts), methods ``iq:auto``,
``iq:clarabel``, ``iq:nsgs`` (:data:`IQ_METHODS`; the ``fclib-wide`` suite runs the default
alone, :data:`SUITE_IQ_METHODS`) and ``siconos:NSGS``, ``siconos:NSN_AC``, ``siconos:PROX``
(:data:`SICONOS_SOLVERS`, served by :mod:`benchmarks.siconos_worker` in Debian's Python;
skipped when it cannot import siconos). On 2-D problems Siconos' NSGS is its fc2d NSGS, and
NSN_AC and PROX, which Siconos 4.4 has in 3-D only, are failures (∞ in the profile).

Where the default does not certify, ``solve_friction`` raises ``CertificateError`` carrying
its best answer and the attempts: the row keeps the time spent and the ABH error of that
best answer, recomputed here from its r.
"""

from __future__ import annotations

import math
import multiprocessing
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import impactqp as iq
from impactqp.io.siconos_text import write_siconos_text
from impactqp.model.friction import FrictionCertificate, certify_friction

from . import friction_data
from .friction_data import FrictionCase
from .measure import quiet_stdout, row
from .simulation import SICONOS_PYTHON, SiconosServer

TOL = 1e-8
"""Tolerance of every solver and of the verdict (ABH error)."""
MAX_ITER = 100_000
"""Siconos' SICONOS_IPARAM_MAX_ITER."""
TIME_LIMIT = 180.0
"""Seconds after which a run, impactqp's or Siconos', is stopped and recorded as failed."""
READ_ALLOWANCE = 10.0
"""Seconds Siconos is given beyond :data:`TIME_LIMIT` and the repeats to read a file."""
WORKER = Path(__file__).with_name("siconos_worker.py")
SICONOS_SOLVERS = ("NSGS", "NSN_AC", "PROX")
"""Siconos 4.4's fc3d solvers compared: nonsmooth Gauss–Seidel, nonsmooth Newton on the
Alart–Curnier function, proximal point."""
IQ_METHODS: dict[str, Callable[[iq.FrictionContactProblem], Any]] = {
    "iq:auto": lambda p: iq.solve_friction(p, tol=TOL),
    "iq:clarabel": lambda p: iq.solve_friction(p, backend="clarabel", tol=TOL),
    "iq:nsgs": lambda p: iq.solve_friction(p, backend="nsgs", tol=TOL),
}
"""impactqp's methods: ``solve_friction`` with each backend (auto is the default)."""
METHODS = (*IQ_METHODS, *(f"siconos:{s}" for s in SICONOS_SOLVERS))
"""Every method of the suite, in the order of the tables and the profile."""
DEFAULT, BASELINE = "iq:auto", "siconos:NSGS"
"""The ratio reported per problem: impactqp's default over Siconos' NSGS."""
#: problems per suite (names of :data:`benchmarks.friction_data.ALL`)
PROBLEMS: dict[str, list[str]] = {
    "quick": ["LMGC-00046"],
    "full": list(friction_data.FILES),
    "friction": list(friction_data.FILES),
    "fclib-wide": list(friction_data.ALL),
}
SUITE_IQ_METHODS: dict[str, tuple[str, ...]] = {"fclib-wide": (DEFAULT,)}
"""impactqp's methods per suite where not all of :data:`IQ_METHODS` (the widened set times the
default beside Siconos, within a CPU budget of minutes)."""
TIME_LIMITS: dict[str, float] = {"fclib-wide": 30.0}
"""Per-problem time limit of a suite's runs where not :data:`TIME_LIMIT` (seconds)."""
PLANAR_SOLVERS = ("NSGS",)
"""Siconos' solvers of :data:`SICONOS_SOLVERS` that its fc2d_driver has (2-D problems)."""
IQ_NOTE = ("iq.solve_friction(problem, backend=…, tol=1e-8) on the loaded problem; error = "
           "ABH recomputed by certify_friction")
PEER_NOTE = ("fc3d_driver (fc2d_driver in 2-D) from r = 0 (tol 1e-8, ≤ 1e5 iterations), W "
             "sparse-block as Siconos reads its own text files, in /usr/bin/python3; error = "
             "ABH recomputed by impactqp's certify_friction from Siconos' r")


def _child(conn: Any, method: Callable[[Any], Any], problem: Any) -> None:
    """Run ``method(problem)`` once in a forked process; send back its seconds and r, u
    (or the exception's text, with the best answer's r and the attempts of a
    ``CertificateError``)."""
    t0 = time.perf_counter()
    try:
        result = method(problem)
        conn.send(("ok", time.perf_counter() - t0, result.r, result.u, result.backend))
    except Exception as exc:  # e.g. CertificateError: a failure with its time spent
        seconds = time.perf_counter() - t0
        best = getattr(exc, "best", None)
        conn.send(("error", seconds, f"{type(exc).__name__}: {exc}",
                   None if best is None else np.asarray(best.r),
                   list(getattr(exc, "attempts", []))))
    conn.close()


def first_run(method: Callable[[Any], Any], problem: Any,
              limit: float = TIME_LIMIT) -> tuple[str, float, Any]:
    """The first (timed) run of an impactqp method, in a forked copy of this process (its
    compiled kernels included) that is stopped after ``limit`` seconds, as Siconos' runs.

    Clarabel runs on one thread in the copy (:mod:`impactqp.qp.backends.clarabel_`): the
    thread pool it had started here, on an earlier large problem, is not in the copy, which
    used to wait for it until the limit (iq:clarabel on KaplasTower in the full suite). One
    thread or the pool: the same answer, and the same time on KaplasTower (1.32–1.39 s
    against 1.37–2.25 s, measured in one process).

    Returns
    -------
    ("ok", seconds, (r, u, route)), ("error", seconds, (message, best r or None, attempts))
    or ("stopped", limit, "")
    """
    ctx = multiprocessing.get_context("fork")
    receive, send = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(send, method, problem), daemon=True)
    proc.start()
    send.close()
    try:
        if not receive.poll(limit):
            proc.kill()
            return "stopped", limit, ""
        try:
            status, seconds, *rest = receive.recv()
        except EOFError:  # the child died without a word
            return "error", limit, f"the solving process died (exit {proc.exitcode})"
    finally:
        proc.join()
        receive.close()
    return status, seconds, tuple(rest)


def _repeat(run: Callable[[], Any], budget: float, max_repeats: int) -> list[float]:
    """One untimed warm-up of a quick solve, then timed repeats until ``budget`` seconds or
    ``max_repeats`` runs."""
    run()
    times: list[float] = []
    start = time.perf_counter()
    while len(times) < max_repeats and (not times or time.perf_counter() - start < budget):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return times


def verdict(cert: FrictionCertificate) -> tuple[str, str]:
    """(status, message) of an answer: ``ok`` when its ABH error is within :data:`TOL`;
    the other residuals of the certificate are named in the message when they fail."""
    extra = [f"{k} {v:.1e}" for k, v in cert.values.items()
             if k != "natural_map" and not v <= TOL]
    note = f" ({', '.join(extra)} above {TOL:g})" if extra else ""
    if cert.error <= TOL:
        return "ok", f"ABH {cert.error:.1e}{note}" if note else ""
    return "failed", f"ABH {cert.error:.1e} > {TOL:g}{note}"


def warm_up() -> None:
    """Compile impactqp's friction kernels (numba) on a one-contact problem, untimed."""
    W = np.array([[2.0, 0.1, 0.0], [0.1, 1.5, 0.0], [0.0, 0.0, 1.5]])
    p = iq.FrictionContactProblem(W, np.array([-1.0, 0.4, 0.2]), 0.3)
    for method in IQ_METHODS.values():
        method(p)


def _failure(case: FrictionCase, out: Any, seconds: float) -> tuple[str, float | None]:
    """(message, ABH error of the best answer) of a run that did not certify: the error is
    recomputed here from the best r a ``CertificateError`` carried (None without one)."""
    if not out:
        return f"stopped after {seconds:g} s", None
    message, best_r, attempts = out
    if best_r is None:
        return message, None
    error = certify_friction(case.problem, best_r, tol=TOL).error
    return (f"best answer ABH {error:.1e} (recomputed) after {len(attempts)} attempts; "
            f"{message}", error if math.isfinite(error) else None)


def run_impactqp(case: FrictionCase, *, budget: float, max_repeats: int,
                 methods: tuple[str, ...] = tuple(IQ_METHODS),
                 limit: float = TIME_LIMIT) -> list[dict]:
    """One row per method of ``methods`` (names of :data:`IQ_METHODS`) on ``case``: the
    first run counts alone when it takes the budget (a solve of seconds needs no warm-up;
    one stopped at ``limit`` seconds fails), else it is the warm-up and timed repeats follow
    — the rule of Siconos' side too."""
    rows = []
    for name in methods:
        method = IQ_METHODS[name]
        with quiet_stdout():
            status, seconds, out = first_run(method, case.problem, limit)
            times = [seconds]
            if status == "ok" and seconds < budget:
                try:
                    times = _repeat(lambda m=method: m(case.problem), budget, max_repeats)
                except Exception as exc:  # solved in the child, not here: a failure
                    status, out = "error", (f"{type(exc).__name__}: {exc}", None, [])
        if status != "ok":
            message, error = _failure(case, out, seconds)
            rows.append(_row(case, name, "impactqp", "failed", times, error, message,
                             IQ_NOTE))
            continue
        r, u, route = out
        cert = certify_friction(case.problem, r, u, tol=TOL)
        status, message = verdict(cert)
        rows.append(_row(case, name, "impactqp", status, times, cert.error,
                         message or f"route {route}", IQ_NOTE))
    return rows


def _row(case: FrictionCase, method: str, group: str, status: str, times: list[float],
         error: float | None, message: str, note: str) -> dict:
    return row(case.family, case.n_contacts, method, group, status=status, times=times,
               error=error, message=message, note=note,
               reference=f"{case.path.name}: ABH error by impactqp's certify_friction")


class SiconosPeer:
    """Siconos' fc3d solvers in a server process (restarted after a crash or a stop)."""

    def __init__(self, python: str) -> None:
        self.python = python
        self.server: SiconosServer | None = None
        self.tmp = tempfile.TemporaryDirectory()

    def solve(self, case: FrictionCase, solver: str, *, budget: float,
              max_repeats: int, limit: float = TIME_LIMIT) -> dict:
        """Run one solver on ``case``; its row (failed rows keep the time spent)."""
        name = f"siconos:{solver}"
        if case.problem.contact_dim == 2 and solver not in PLANAR_SOLVERS:
            return _row(case, name, "peer", "failed", [], None,
                        f"Siconos 4.4 has no 2-D {solver} (fc2d_driver: NSGS, CPG, Lemke, "
                        "enumeration)", PEER_NOTE)
        path = Path(self.tmp.name) / f"{case.name}.dat"
        if not path.exists():
            write_siconos_text(case.problem, path)
        if self.server is None or not self.server.alive:
            self.server = SiconosServer(self.python, WORKER, "--fc3d-serve")
        job = {"path": str(path), "solver": solver, "tol": TOL, "max_iter": MAX_ITER,
               "budget": budget, "max_repeats": max_repeats}
        t0 = time.perf_counter()
        try:
            answer = self.server.request(job, timeout=limit + 2 * budget + READ_ALLOWANCE)
        except TimeoutError as exc:
            self.server = None
            return _row(case, name, "peer", "failed", [time.perf_counter() - t0], None,
                        f"stopped: {exc}", PEER_NOTE)
        except RuntimeError as exc:
            return _row(case, name, "peer", "failed", [], None, str(exc), PEER_NOTE)
        cert = certify_friction(case.problem, np.asarray(answer["r"]),
                                np.asarray(answer["u"]), tol=TOL)
        status, message = verdict(cert)
        own = (f"Siconos info {answer['info']}, {answer['iterations']} iterations, its own "
               f"error {answer['siconos_error']:.1e}")
        return _row(case, name, "peer", status, answer["times"], cert.error,
                    f"{message}; {own}" if message else own, PEER_NOTE)

    def close(self) -> None:
        if self.server is not None:
            self.server.close()
        self.tmp.cleanup()


def _peer_status(python: str) -> str | None:
    """None when ``python`` imports siconos.numerics, else why not."""
    from .peers import siconos_status

    return siconos_status(python) if python else "no Siconos interpreter given"


def run_friction(suite: str, *, budget: float, max_repeats: int,
                 siconos_python: str = SICONOS_PYTHON,
                 progress: Callable[[str], None] | None = None) -> list[dict]:
    """Rows of the friction suite's problems for ``suite`` (none for suites without)."""
    names = PROBLEMS.get(suite, [])
    if not names:
        return []
    methods = SUITE_IQ_METHODS.get(suite, tuple(IQ_METHODS))
    limit = TIME_LIMITS.get(suite, TIME_LIMIT)
    warm_up()
    why = _peer_status(siconos_python)
    peer = SiconosPeer(siconos_python) if why is None else None
    rows: list[dict] = []
    try:
        for name in names:
            case = friction_data.load(name)
            if progress:
                progress(name)
            rows += run_impactqp(case, budget=budget, max_repeats=max_repeats,
                                 methods=methods, limit=limit)
            for solver in SICONOS_SOLVERS:
                if peer is None:
                    rows.append(_row(case, f"siconos:{solver}", "peer", "skipped", [], None,
                                     f"siconos not importable by {siconos_python}: {why}",
                                     PEER_NOTE))
                else:
                    rows.append(peer.solve(case, solver, budget=budget,
                                           max_repeats=max_repeats, limit=limit))
    finally:
        if peer is not None:
            peer.close()
    return rows
