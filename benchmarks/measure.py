"""Timing one method on one case, its accuracy, and the record the reports are made from."""

from __future__ import annotations

import contextlib
import os
import sys
import time
import tracemalloc
import warnings
from collections.abc import Iterator
from typing import Any

import numpy as np

from .families import Case
from .methods import Method

#: relative velocity error up to which an answer counts as a success
ACCURATE = 1e-6
#: cases with at least this bulk (max(n, m), or k) get their peak memory measured
LARGE = 10_000


def relative_error(case: Case, u_plus: np.ndarray, *, law: str = "moreau") -> float:
    """max ‖u⁺ − u⁺_ref‖_M / ‖u⁻‖_M (over the sampled rows for a batch)."""
    st = case.problem.structure
    if case.U is None:
        diff = np.asarray(u_plus) - case.reference
        return case.problem.norm(diff) / case.problem.velocity_scale
    ref = case.extra["sorted"] if law == "sector" else case.reference
    rows = np.asarray(u_plus)[case.sample]
    U = case.U[case.sample]
    num = np.sqrt(np.einsum("ij,ij->i", st.mass_rows(rows - ref), rows - ref))
    den = np.sqrt(np.einsum("ij,ij->i", st.mass_rows(U), U))
    return float(np.max(num / np.where(den > 0, den, 1.0)))


def fmt_time(seconds: float | None) -> str:
    """Seconds as "1.23 ms" (three significant digits, s, ms, µs or ns); "—" for None."""
    if seconds is None:
        return "—"
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds * 1e9:.3g} ns"


def missed_by(factor: float) -> str:
    """The verdict of a target missed by ``factor`` (> 1): "MISSED by 1.3×", with as many
    digits as it takes for the factor not to read as 1 (1.04×, 1.004×): a miss never prints
    as "MISSED by 1.0×"."""
    digits = 1
    while digits < 6 and float(f"{factor:.{digits}f}") <= 1.0:
        digits += 1
    return f"MISSED by {factor:.{digits}f}×"


def output_size(raw: Any) -> float | None:
    """MB of a batch result's own arrays (u⁺, Λ, the residuals): what peak memory must hold
    anyway, so that what a batch needs beyond input and output can be told apart."""
    residuals = getattr(raw, "residuals", None)
    if not isinstance(residuals, dict):
        return None
    arrays = [raw.u_plus, raw.impulses, *residuals.values()]
    return sum(a.nbytes for a in arrays) / 2**20


def row(family: str, size: float, method: str, group: str, *, status: str,
        message: str = "", times: list[float] | None = None, error: float | None = None,
        peak_mb: float | None = None, note: str = "", output_mb: float | None = None,
        reference: str = "", instance: int = 0) -> dict[str, Any]:
    """One tidy row of the reports: a method on one instance of ``family`` at ``size``."""
    return {"family": family, "size": size, "instance": instance,
            "method": method, "group": group, "status": status, "message": message[:300],
            "times": list(times or []), "error": error, "peak_mb": peak_mb,
            "output_mb": output_mb, "reference": reference, "note": note}


def record(case: Case, method: str, group: str, **fields: Any) -> dict[str, Any]:
    """One tidy row: a method on one case instance (fields as in :func:`row`)."""
    return row(case.family, case.size, method, group, instance=case.instance,
               reference=case.ref_label, **fields)


@contextlib.contextmanager
def quiet_stdout() -> Iterator[None]:
    """Silence what native solvers print on file descriptor 1, and Python warnings."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as null, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        os.dup2(null.fileno(), 1)
        try:
            yield
        finally:
            sys.stdout.flush()
            os.dup2(saved, 1)
            os.close(saved)


def _first_run(solve: Any, track_memory: bool) -> tuple[Any, float | None]:
    """The untimed warm-up (fills the problem's caches); under tracemalloc when asked."""
    if not track_memory:
        return solve(), None
    tracemalloc.start()
    try:
        raw = solve()
        peak = tracemalloc.get_traced_memory()[1] / 2**20
    finally:
        tracemalloc.stop()
    return raw, peak


def measure(method: Method, case: Case, *, budget: float, max_repeats: int) -> dict[str, Any]:
    """Prepare, warm up, then time ``solve()`` until ``budget`` seconds or ``max_repeats``.

    Never raises: an exception in any step is recorded as a failure with its message.
    """
    why = method.skip_reason(case)
    if why is not None:
        return record(case, method.name, method.group, status="skipped", message=why,
                      note=method.note)
    try:
        with quiet_stdout():
            solve, finish = method.prepare(case)
            raw, peak = _first_run(solve, case.work >= LARGE)
            err, output_mb = relative_error(case, finish(raw), law=method.law), output_size(raw)
            # Released before timing: otherwise every timed run of a large batch writes its
            # output into pages the process has never touched, and on a virtual machine that
            # backs memory lazily that first touch can cost more than the solve itself.
            del raw
            times: list[float] = []
            start = time.perf_counter()
            while len(times) < max_repeats and (not times or time.perf_counter() - start < budget):
                t0 = time.perf_counter()
                solve()
                times.append(time.perf_counter() - t0)
    except Exception as exc:  # a failing method is a result, never an abort
        return record(case, method.name, method.group, status="failed",
                      message=f"{type(exc).__name__}: {exc}", note=method.note)
    status = "ok" if err <= ACCURATE else "inaccurate"
    return record(case, method.name, method.group, status=status, times=times, error=err,
                  peak_mb=peak, note=method.note, output_mb=output_mb,
                  message="" if status == "ok" else f"relative error {err:.1e}")
