"""The sweep benchmark: one Frémond admissibility map on 1 and on ``n_jobs`` local processes
(2 by default).

A sweep is the same seeded work split into chunks; the report compares the two times and
checks that the two maps are identical.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

import impactqp as iq

#: per suite: (grid points of a, of b, sampled u⁻ per cell, timed runs per worker count)
SWEEPS = {"quick": (4, 4, 40, 1), "full": (14, 14, 300, 2)}


def _row(cells: int, jobs: int, times: list[float], same: bool) -> dict[str, Any]:
    return {"family": "sweep", "size": cells, "instance": 0,
            "method": f"iq:fremond_map n_jobs={jobs}", "group": "sweep",
            "status": "ok" if same else "inaccurate",
            "message": "" if same else "maps differ between worker counts",
            "times": times, "error": 0.0 if same else 1.0, "peak_mb": None,
            "output_mb": None, "reference": "the n_jobs=1 map",
            "note": "Frémond admissibility map of the 3-ball cradle"}


def run_sweeps(suite: str, n_jobs: int = 2) -> list[dict[str, Any]]:
    """Records of the sweep family for ``suite`` (none for suites without one): the map on
    one process and on ``n_jobs`` processes."""
    if suite not in SWEEPS:
        return []
    jobs_tried = (1, n_jobs) if n_jobs > 1 else (1,)
    na, nb, samples, runs = SWEEPS[suite]
    p = iq.newtons_cradle(3)
    a, b = np.linspace(0.0, 1.0, na), np.linspace(-0.5, 1.0, nb)
    maps, times = {}, {}
    for jobs in jobs_tried:
        times[jobs] = []
        for _ in range(runs):
            t0 = time.perf_counter()
            maps[jobs] = iq.verification.fremond_admissibility_map(p, a, b, samples=samples, seed=0,
                                                      n_jobs=jobs, progress=False)
            times[jobs].append(time.perf_counter() - t0)
    same = all(np.array_equal(maps[1], maps[j]) for j in jobs_tried)
    return [_row(na * nb, jobs, times[jobs], same) for jobs in jobs_tried]
