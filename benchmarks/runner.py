"""Run a suite: build each case (untimed), time every method on it, then the Siconos peer."""

from __future__ import annotations

import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TextIO

from . import families, peers, report
from .families import Case
from .measure import measure, quiet_stdout
from .methods import METHODS, Method

#: per suite: (seconds of timed repeats per method and case, most repeats)
TIMING = {"smoke": (0.01, 10), "quick": (0.02, 30), "full": (0.3, 500)}


class Progress:
    """A one-line progress bar on a text stream (stderr by default)."""

    def __init__(self, total: int, *, stream: TextIO | None = None, width: int = 30) -> None:
        self.total, self.done, self.width = max(total, 1), 0, width
        self.stream = stream if stream is not None else sys.stderr
        self.start = self.shown = time.perf_counter()

    def step(self, label: str, n: int = 1) -> None:
        """Advance by ``n`` and show ``label`` (what runs next)."""
        self.done = min(self.done + n, self.total)
        now = time.perf_counter()
        if now - self.shown < 0.1 and self.done < self.total:
            return  # redraw at most ten times a second
        self.shown = now
        filled = self.width * self.done // self.total
        bar = "#" * filled + "." * (self.width - filled)
        elapsed = now - self.start
        self.stream.write(f"\r[{bar}] {self.done}/{self.total} {elapsed:6.1f}s {label[:48]:<48}")
        self.stream.flush()

    def close(self) -> None:
        self.stream.write("\n")
        self.stream.flush()


def run_suite(suite: str, out_dir: Path | str, *, methods: Sequence[Method] | None = None,
              siconos_python: str = peers.SICONOS_PYTHON,
              progress: bool = True) -> list[dict[str, Any]]:
    """Run ``suite`` and write results.csv, results.json, summary.md and plot.png.

    Parameters
    ----------
    suite : {"smoke", "quick", "full"}
    out_dir : path
        Created when missing.
    methods : sequence of Method, optional
        Default: :data:`benchmarks.methods.METHODS`.
    siconos_python : str
        The interpreter that runs :mod:`benchmarks.siconos_worker` (``""`` skips the peer).
    progress : bool
        Show a progress bar on stderr.

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
    bar = Progress(n_cases * (len(methods) + 1) + 1, stream=None if progress else _Null())
    records: list[dict[str, Any]] = []
    peer_cases: list[Case] = []
    started = time.perf_counter()
    for case in families.cases(suite):
        bar.step(f"{case.label}: reference")
        with quiet_stdout():
            families.attach_reference(case)
        for method in methods:
            bar.step(f"{case.label}: {method.name}")
            records.append(measure(method, case, budget=budget, max_repeats=max_repeats))
        if siconos_python and peers.wants(case):
            peer_cases.append(case)
    bar.step("siconos peer")
    if siconos_python:
        why = peers.siconos_status(siconos_python)
        if why is not None:
            print(f"\nnotice: Siconos is skipped ({siconos_python} cannot import "
                  f"siconos.numerics: {why})", file=sys.stderr)
        records += peers.run_siconos(peer_cases, budget=budget, max_repeats=max_repeats,
                                     python=siconos_python)
    bar.close()
    meta = {"suite": suite, "seconds": round(time.perf_counter() - started, 1),
            "timing_budget_s": budget, "max_repeats": max_repeats,
            "accurate_below": peers.ACCURATE}
    report.write_all(records, Path(out_dir), meta)
    return records


class _Null:
    """A stream that drops everything (progress bar switched off)."""

    def write(self, text: str) -> int:
        return len(text)

    def flush(self) -> None:
        return None
