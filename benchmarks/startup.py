"""Start-up cost: the first impacts in a fresh process, with numba's compile cache cold and warm.

    python -m benchmarks.startup [--repeats 3]

impactqp's kernels are compiled by numba on first use and cached on disk. Each measurement
runs a fresh interpreter that imports impactqp and solves, in turn, a 3-ball cradle with
``iq.moreau``, a random dense 10-contact impact, a 10⁴-ball cradle (the chain passes) and a
batch of 3-ball impacts, printing the seconds each first call took and then what the same
call costs once warm. "cold" points numba at an empty cache folder (what the first run after
an install pays, once); "warm" reuses the folder the cold run filled (every later process).
Printed: the median over ``repeats`` processes of each, as JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

PROBE = r"""
import json, time
t0 = time.perf_counter()
import numpy as np
import impactqp as iq
out = {"import": time.perf_counter() - t0}
rng = np.random.default_rng(0)
A = rng.standard_normal((10, 10))
cases = {
    "cradle3": (iq.newtons_cradle(3), None),
    "dense10": (iq.ImpactProblem(A @ A.T + 10 * np.eye(10), rng.standard_normal((10, 10)),
                                 rng.standard_normal(10)), None),
    "chain1e4": (iq.newtons_cradle(10_000), None),
    "batch3": (iq.newtons_cradle(3), rng.standard_normal((1000, 3))),
}
for name, (p, rows) in cases.items():
    call = (lambda: iq.moreau(p, 0.5)) if rows is None else (lambda: iq.moreau_batch(p, rows))
    t = time.perf_counter(); call(); first = time.perf_counter() - t
    t = time.perf_counter(); call(); again = time.perf_counter() - t
    out[name] = first
    out[name + " (warm call)"] = again
print(json.dumps(out))
"""


def probe(cache: str | None = None, python: str = sys.executable) -> dict[str, float]:
    """Seconds of one fresh process (import, first and second call of each case); numba's
    cache in the folder ``cache``, or where the environment puts it when None."""
    env = dict(os.environ) if cache is None else {**os.environ, "NUMBA_CACHE_DIR": cache}
    done = subprocess.run([python, "-c", PROBE], env=env, capture_output=True,
                          text=True, check=True, timeout=600)
    return json.loads(done.stdout.strip().splitlines()[-1])


def first_call_extra(runs: dict[str, float]) -> float:
    """Seconds the first calls of a probe cost beyond the same calls warm."""
    return sum(runs[name] - runs[name + " (warm call)"] for name in runs
               if name + " (warm call)" in runs)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.startup", description=__doc__)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    cold, warm = [], []
    for _ in range(args.repeats):
        with tempfile.TemporaryDirectory() as cache:
            cold.append(probe(cache))
            warm.append(probe(cache))
    result = {label: {key: statistics.median(run[key] for run in runs) for key in runs[0]}
              for label, runs in (("cold cache", cold), ("warm cache", warm))}
    print(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
