"""``--suite fclib --collection DIR``: a whole folder of FCLib/Siconos problems through
impactqp's friction methods (:func:`impactqp.collection.run_collection`: here, on local
processes or on a Dask scheduler) and, where Siconos imports, its fc3d solvers on the same
files, every outcome one line of the same JSON Lines file; then a summary.

Siconos' answers are judged as impactqp's: the ABH error recomputed by
:func:`impactqp.model.friction.certify_friction` from its r (``"certified"`` at most the
tolerance). Both sides run each problem once from r = 0 (impactqp's kernels compiled before,
Siconos reading its file before its timer) under the same time limit; Siconos' solvers run
here, one after the other (on 2-D problems only those its fc2d driver has). The output is resumable:
a rerun solves only the (file, method) pairs it lacks.
"""

from __future__ import annotations

import math
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

import impactqp as iq
from impactqp.collection import run_collection
from impactqp.io.collection import collection_files
from impactqp.io.journal import Journal
from impactqp.io.siconos_text import write_siconos_text
from impactqp.model.friction import certify_friction

from .friction import (
    MAX_ITER,
    PLANAR_SOLVERS,
    READ_ALLOWANCE,
    SICONOS_SOLVERS,
    TIME_LIMIT,
    TOL,
    WORKER,
)
from .simulation import SICONOS_PYTHON, SiconosServer

DEFAULT, BASELINE = "auto", "siconos:NSGS"
"""The ratio of the summary: impactqp's default route over Siconos' NSGS."""


def run_fclib_collection(folder: Path, output: Path, *, methods: Sequence[str] = (DEFAULT,),
                         time_limit: float | None = None, n_jobs: int = 1,
                         scheduler: str | None = None,
                         siconos_python: str = SICONOS_PYTHON,
                         progress: Callable[[str], None] | None = None) -> list[dict]:
    """Every record of the collection in ``output`` (impactqp's, then Siconos')."""
    note = (lambda r: progress(f"{r['method']} {r['file']}: {r['status']}")) if progress \
        else None
    run = run_collection(folder, output, methods=methods, time_limit=time_limit, tol=TOL,
                         n_jobs=n_jobs, scheduler=scheduler, on_record=note)
    records = list(run.records)
    if siconos_python:
        records += run_siconos(folder, output, run.records, python=siconos_python,
                               time_limit=time_limit, on_record=note)
    return records


def run_siconos(folder: Path, output: Path, iq_records: list[dict], *, python: str,
                time_limit: float | None,
                on_record: Callable[[dict], None] | None = None) -> list[dict]:
    """Siconos' solvers on every problem impactqp read (on 2-D ones those of its fc2d
    driver, :data:`~benchmarks.friction.PLANAR_SOLVERS`), records appended to ``output``
    (those there already kept); none when ``python`` cannot import siconos (a notice)."""
    from .peers import siconos_status

    why = siconos_status(python)
    if why is not None:
        print(f"notice: Siconos is skipped ({python} cannot import siconos.numerics: {why})",
              file=sys.stderr)
        return []
    journal = Journal(output)
    done = {(r["file"], r["method"]): r for r in journal.records()}
    dims = {r["file"]: r["d"] for r in iq_records if r["d"] is not None}
    files = [f for f in collection_files(folder) if f in dims]
    server: SiconosServer | None = None
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        try:
            for name in files:
                solvers = PLANAR_SOLVERS if dims[name] == 2 else SICONOS_SOLVERS
                todo = [s for s in solvers if (name, f"siconos:{s}") not in done]
                if not todo:
                    out += [done[(name, f"siconos:{s}")] for s in solvers]
                    continue
                problem = iq.load_fclib(folder / name)
                text = Path(tmp) / "problem.dat"
                write_siconos_text(problem, text)
                for solver in solvers:
                    if solver not in todo:
                        out.append(done[(name, f"siconos:{solver}")])
                        continue
                    if server is None or not server.alive:
                        server = SiconosServer(python, WORKER, "--fc3d-serve")
                    record = _siconos_once(server, problem, text, name, solver, time_limit)
                    journal.append(record)
                    out.append(record)
                    if on_record is not None:
                        on_record(record)
        finally:
            if server is not None:
                server.close()
    return out


def _siconos_once(server: SiconosServer, problem: iq.FrictionContactProblem, text: Path,
                  name: str, solver: str, time_limit: float | None) -> dict:
    """One run of ``solver`` from r = 0; its record, judged by impactqp's certificate."""
    limit = TIME_LIMIT if time_limit is None else time_limit
    mu = np.asarray(problem.mu, dtype=float)
    record: dict[str, Any] = {
        "file": name, "method": f"siconos:{solver}", "status": None, "error_name": None,
        "message": "", "contacts": problem.n_contacts, "d": problem.contact_dim,
        "mu_min": float(mu.min()), "mu_max": float(mu.max()), "read_seconds": None,
        "seconds": None, "cpu_seconds": None, "iterations": None, "abh_error": None,
        "backend": solver,
        "r_norm": None, "tol": TOL}
    job = {"path": str(text), "solver": solver, "tol": TOL, "max_iter": MAX_ITER,
           "budget": 0.0, "max_repeats": 1}
    t0 = time.perf_counter()
    try:
        answer = server.request(job, timeout=limit + READ_ALLOWANCE)
    except TimeoutError:
        return {**record, "status": "time limit", "seconds": time.perf_counter() - t0,
                "message": f"stopped (time limit {limit:g} s)"}
    except RuntimeError as exc:
        return {**record, "status": "error", "error_name": "SiconosError",
                "message": str(exc)[:500]}
    r, u = np.asarray(answer["r"]), np.asarray(answer["u"])
    cert = certify_friction(problem, r, u, tol=TOL)
    seconds = answer["times"][0]
    record.update(seconds=seconds, iterations=answer["iterations"],
                  abh_error=float(cert.error), r_norm=float(np.linalg.norm(r)),
                  message=f"Siconos info {answer['info']}, its own error "
                          f"{answer['siconos_error']:.1e}")
    if seconds > limit:
        record.update(status="time limit")
    else:
        record.update(status="certified" if cert.error <= TOL else "not certified")
    return record


def summary(records: list[dict], profile: Path | None = None) -> str:
    """Certified counts per method, the geometric mean of impactqp's default time over
    NSGS' on the problems both certify, and (with ``profile``) the Dolan–Moré profile of
    every method over the collection's problems written there."""
    methods = list(dict.fromkeys(r["method"] for r in records))
    files = list(dict.fromkeys(r["file"] for r in records))
    by = {(r["file"], r["method"]): r for r in records}
    lines = [f"{len(files)} files, tolerance {TOL:g} (ABH error)", "",
             "| method | certified | not certified | time limit | error |", "|---|---|---|---|---|"]
    for m in methods:
        counts = [sum(1 for f in files if by.get((f, m), {}).get("status") == s)
                  for s in ("certified", "not certified", "time limit", "error")]
        lines.append(f"| {m} | " + " | ".join(map(str, counts)) + " |")
    if any(r["d"] == 2 for r in records) and any(m.startswith("siconos:") for m in methods):
        lines += ["", f"On 2-D files Siconos 4.4 runs {', '.join(PLANAR_SOLVERS)} only (its "
                  "fc2d driver): its other solvers' counts are of the 3-D files."]
    ratios = [by[(f, DEFAULT)]["seconds"] / by[(f, BASELINE)]["seconds"] for f in files
              if all(by.get((f, m), {}).get("status") == "certified" for m in (DEFAULT, BASELINE))]
    if ratios:
        mean = math.exp(float(np.mean(np.log(ratios))))
        lines += ["", f"{DEFAULT} / {BASELINE}, geometric mean over the {len(ratios)} problems "
                  f"both certify: {mean:.2f}× (one run each)"]
        own = [by[(f, DEFAULT)] for f in files if by.get((f, DEFAULT), {}).get("cpu_seconds")]
        share = sum(r["cpu_seconds"] for r in own) / sum(r["seconds"] for r in own) if own \
            else 1.0
        if share < 0.9:  # the solves waited for a processor: their times are inflated
            lines.append(f"{DEFAULT}'s solves were on a processor {share:.0%} of their time "
                         "(a busy machine, or --n-jobs beside each other): the ratio is "
                         "pessimistic; --n-jobs 1 on a quiet machine times them fairly")
    if profile is not None and len(methods) > 1:
        from .perf_profile import plot_profile

        times = {m: [by[(f, m)]["seconds"] if by.get((f, m), {}).get("status") == "certified"
                     else math.inf for f in files] for m in methods}
        plot_profile(times, profile, title=f"Dolan–Moré profile, {len(files)} files")
        lines += ["", f"Dolan–Moré profile: {profile}"]
    return "\n".join(lines)
