"""Time Siconos' LCP solvers on impact LCPs; runs under Debian's /usr/bin/python3 only.

Usage: ``/usr/bin/python3 siconos_worker.py IN.json OUT.json``. IN holds
``{"budget": seconds, "max_repeats": int, "problems": [{"id", "M", "q", "solvers"}]}``
with the LCP ``0 ≤ z ⟂ Mz + q ≥ 0`` (M = G, q = (1+ε)γ⁻) and solver names among
``lemke``, ``pgs``, ``enum``. Each timed run builds the ``sn.LCP`` object from the numpy
arrays and the solver options, then calls the driver (as a user of Siconos from Python
would). OUT holds per problem and solver the run times, the median, z, and Siconos' info
code (0 = solved). With ``--check`` it only verifies that siconos imports.

This file must stay importable without siconos and self-contained (no impactqp import).
"""

from __future__ import annotations

import json
import statistics
import sys
import time


def _solver_ids(sn) -> dict:
    return {"lemke": sn.SICONOS_LCP_LEMKE, "pgs": sn.SICONOS_LCP_PGS,
            "enum": sn.SICONOS_LCP_ENUM}


def run_one(sn, np, M, q, solver_id: int) -> tuple[int, list]:
    """Build the LCP and its options from arrays, solve; return (info, z)."""
    lcp = sn.LCP(M, q)
    z = np.zeros(q.size)
    w = np.zeros(q.size)
    options = sn.SolverOptions(solver_id)
    info = sn.linearComplementarity_driver(lcp, z, w, options)
    return int(info), z.tolist()


def time_solver(sn, np, M, q, solver_id: int, budget: float, max_repeats: int) -> dict:
    """Warm up once, then repeat until ``budget`` seconds or ``max_repeats`` runs."""
    info, z = run_one(sn, np, M, q, solver_id)
    times: list[float] = []
    start = time.perf_counter()
    while len(times) < max_repeats and (not times or time.perf_counter() - start < budget):
        t0 = time.perf_counter()
        run_one(sn, np, M, q, solver_id)
        times.append(time.perf_counter() - t0)
    return {"info": info, "z": z, "times": times, "median": statistics.median(times)}


def main(argv: list[str]) -> int:
    """Entry point; returns the exit status (3 when siconos cannot be imported)."""
    try:
        import numpy as np
        import siconos.numerics as sn
    except ImportError as exc:
        print(f"siconos unavailable: {exc}", file=sys.stderr)
        return 3
    if argv[1:] == ["--check"]:
        return 0
    with open(argv[1]) as fh:
        job = json.load(fh)
    ids = _solver_ids(sn)
    out = []
    for prob in job["problems"]:
        M = np.ascontiguousarray(prob["M"], dtype=float)
        q = np.asarray(prob["q"], dtype=float)
        results = {}
        for name in prob["solvers"]:
            try:
                results[name] = time_solver(sn, np, M, q, ids[name], job["budget"],
                                            job["max_repeats"])
            except Exception as exc:  # a failing solver is a result, not an abort
                results[name] = {"error": f"{type(exc).__name__}: {exc}"}
        out.append({"id": prob["id"], "results": results})
    with open(argv[2], "w") as fh:
        json.dump({"problems": out}, fh)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
