"""Run a suite: build each case (untimed), time every method on it, then the Siconos peer."""

from __future__ import annotations

import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from tqdm import tqdm

from . import families, peers, report
from .dynamics import run_per_impact, run_simulations, run_startup
from .families import Case
from .friction import run_friction
from .friction_impacts import run_friction_impacts
from .measure import measure, quiet_stdout
from .methods import METHODS, Method
from .sweeps import run_sweeps

#: per suite: (seconds of timed repeats per method and case, most repeats)
TIMING = {"smoke": (0.01, 10), "quick": (0.02, 30), "full": (0.3, 500),
          "friction": (0.3, 500), "fclib-wide": (0.1, 100)}
#: families a suite's rows belong to when they replace rows of earlier results (``merge``)
FRICTION_FAMILIES = ("friction:", "friction-impact")


def run_suite(suite: str, out_dir: Path | str, *, methods: Sequence[Method] | None = None,
              siconos_python: str = peers.SICONOS_PYTHON,
              progress: bool = True, n_jobs: int = 2,
              merge: bool = False) -> list[dict[str, Any]]:
    """Run ``suite`` and write results.csv, results.json, summary.md and plot.png (and
    friction_profile.png with friction rows).

    Parameters
    ----------
    suite : {"smoke", "quick", "full", "friction"}
        ``friction``: the friction rows alone (FCLib problems beside Siconos' fc3d solvers,
        frictional impacts of spheres).
    out_dir : path
        Created when missing.
    methods : sequence of Method, optional
        Default: :data:`benchmarks.methods.METHODS`.
    siconos_python : str
        The interpreter that runs :mod:`benchmarks.siconos_worker` (``""`` skips the peer).
    progress : bool
        Show a progress bar on stderr when stderr is a terminal (never in logs: no
        carriage returns are written to a file or pipe).
    n_jobs : int
        Local processes of the scaled-out sweep, timed against one process (timed methods
        always run one at a time: parallel timings would disturb each other).
    merge : bool
        Keep the records of ``out_dir/results.json`` except those of the families this run
        produces, and write the reports of both (refreshes e.g. only the friction rows of
        benchmarks/reference/).

    Returns
    -------
    list of dict
        One record per case instance and method (see :func:`benchmarks.measure.record`).
    """
    if suite not in families.SUITES:
        raise ValueError(f"suite must be one of {sorted(families.SUITES)}, got {suite!r}")
    methods = list(METHODS if methods is None else methods)
    budget, max_repeats = TIMING[suite]
    n_cases = families.count_cases(suite)
    bar = tqdm(total=n_cases * (len(methods) + 1) + 1, file=sys.stderr, unit="step",
               disable=None if progress else True, dynamic_ncols=True)
    records: list[dict[str, Any]] = []
    peer_cases: list[Case] = []
    started = time.perf_counter()
    for case in families.cases(suite):
        bar.set_postfix_str(f"{case.label}: reference", refresh=False)
        with quiet_stdout():
            families.attach_reference(case)
        bar.update()
        for method in methods:
            bar.set_postfix_str(f"{case.label}: {method.name}", refresh=False)
            records.append(measure(method, case, budget=budget, max_repeats=max_repeats))
            bar.update()
        if siconos_python and peers.wants(case):
            peer_cases.append(case)
    bar.set_postfix_str("siconos peer", refresh=False)
    if siconos_python:
        why = peers.siconos_status(siconos_python)
        if why is not None:
            tqdm.write(f"notice: Siconos is skipped ({siconos_python} cannot import "
                       f"siconos.numerics: {why})", file=sys.stderr)
        records += peers.run_siconos(peer_cases, budget=budget, max_repeats=max_repeats,
                                     python=siconos_python)
    bar.update()
    bar.set_postfix_str(f"sweeps on 1 and {n_jobs} processes", refresh=False)
    records += run_sweeps(suite, n_jobs)
    bar.set_postfix_str("simulations, per-impact timings, start-up", refresh=False)
    records += run_simulations(suite, siconos_python)
    records += run_per_impact(suite)
    records += run_startup(suite)
    bar.set_postfix_str("friction suite", refresh=False)
    friction_started = time.perf_counter()
    records += run_friction(suite, budget=budget, max_repeats=max_repeats,
                            siconos_python=siconos_python,
                            progress=lambda name: bar.set_postfix_str(f"friction: {name}"))
    records += run_friction_impacts(suite)
    bar.close()
    meta = {"suite": suite, "seconds": round(time.perf_counter() - started, 1),
            "timing_budget_s": budget, "max_repeats": max_repeats,
            "accurate_below": peers.ACCURATE,
            "friction_seconds": round(time.perf_counter() - friction_started, 1)}
    if merge:
        records, meta = merge_records(Path(out_dir) / "results.json", records, meta)
    report.write_all(records, Path(out_dir), meta)
    return records


def merge_records(path: Path, records: list[dict[str, Any]],
                  meta: dict[str, Any]) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """The records of ``path`` (a results.json) with those of the families in ``records``
    replaced by ``records``; the old meta, noting the refresh.

    Raises
    ------
    FileNotFoundError
        No results.json to merge into.
    """
    old = json.loads(path.read_text())
    fresh = {r["family"] for r in records}
    kept = [r for r in old["records"] if r["family"] not in fresh
            and not (r["family"].startswith(FRICTION_FAMILIES)
                     and any(f.startswith(FRICTION_FAMILIES) for f in fresh))]
    merged = dict(old["meta"])
    merged["refreshed"] = {"suite": meta["suite"], "seconds": meta["seconds"],
                           "families": sorted(fresh)}
    return kept + records, merged
