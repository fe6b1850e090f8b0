"""Start-up cost: the first impacts in a fresh process, with numba's compile cache cold and warm.

    python -m benchmarks.startup [--repeats 3] [--first-hour]

impactqp's kernels are compiled by numba on first use and cached on disk. Each measurement
runs a fresh interpreter that imports impactqp and solves, in turn, a 3-ball cradle with
``iq.moreau``, a random dense 10-contact impact, a 10⁴-ball cradle (the chain passes) and a
batch of 3-ball impacts, printing the seconds each first call took and then what the same
call costs once warm. "cold" points numba at an empty cache folder (what the first run after
an install pays, once); "warm" reuses the folder the cold run filled (every later process).
Printed: the median over ``repeats`` processes of each, as JSON. These probes compile at
every first call (``IMPACTQP_INTERPRETED_SECONDS=0``): they measure the compile.

``--first-hour`` times instead what a new user meets with impactqp's defaults, each command
in a fresh process with an empty cache: ``impactqp demo`` (its first line, its end), a first
frictional impact, and ``impactqp compile`` (first repeat only), where small first calls run
the kernels' Python text instead of compiling (impactqp/kernels/first_calls.py).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

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


def _env(cache: str | None, interpreted: bool) -> dict[str, str]:
    """The environment of a probe: numba's cache in ``cache`` (where the environment puts it
    when None); small first calls run as Python when ``interpreted`` (impactqp's default),
    else every first call compiles."""
    env = dict(os.environ) if cache is None else {**os.environ, "NUMBA_CACHE_DIR": cache}
    env.pop("IMPACTQP_INTERPRETED_SECONDS", None)
    if not interpreted:
        env["IMPACTQP_INTERPRETED_SECONDS"] = "0"
    return env


def probe(cache: str | None = None, python: str = sys.executable,
          interpreted: bool = False) -> dict[str, float]:
    """Seconds of one fresh process (import, first and second call of each case); numba's
    cache in the folder ``cache``, or where the environment puts it when None; first calls
    compile unless ``interpreted``."""
    env = _env(cache, interpreted)
    done = subprocess.run([python, "-c", PROBE], env=env, capture_output=True,
                          text=True, check=True, timeout=600)
    return json.loads(done.stdout.strip().splitlines()[-1])


def first_call_extra(runs: dict[str, float]) -> float:
    """Seconds the first calls of a probe cost beyond the same calls warm."""
    return sum(runs[name] - runs[name + " (warm call)"] for name in runs
               if name + " (warm call)" in runs)


FRICTIONAL = """
import time
t = time.perf_counter()
import impactqp as iq
p = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])
r = iq.solve(p, iq.Coulomb(0.3, restitution=0.5))
assert r.certificate.ok
print(time.perf_counter() - t)
"""


def _timed_command(command: list[str], env: dict[str, str]) -> tuple[float, float]:
    """Seconds until the command's first line of output (stdout or stderr) and until its
    end; a failing command raises."""
    start = time.perf_counter()
    proc = subprocess.Popen(command, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True)
    assert proc.stdout is not None
    first = None
    for _ in proc.stdout:
        if first is None:
            first = time.perf_counter() - start
    if proc.wait(timeout=900) != 0:
        raise RuntimeError(f"{' '.join(command)} exited with {proc.returncode}")
    end = time.perf_counter() - start
    return (end if first is None else first), end


def first_hour(python: str = sys.executable, compile_all: bool = True) -> dict[str, float]:
    """A new user's first commands, each in a fresh process with an empty cache and
    impactqp's defaults (issue 27's targets: the demo's first line within 2 s and its end
    within 10 s, the first frictional impact within 10 s, ``impactqp compile`` within 60 s).
    Seconds, wall clock."""
    out: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as cache:
        out["demo: first line"], out["demo"] = _timed_command(
            [python, "-m", "impactqp", "demo"], _env(cache, True))
    with tempfile.TemporaryDirectory() as cache:
        start = time.perf_counter()
        subprocess.run([python, "-c", FRICTIONAL], env=_env(cache, True), check=True,
                       capture_output=True, timeout=900)
        out["first frictional impact (process)"] = time.perf_counter() - start
    if compile_all:
        with tempfile.TemporaryDirectory() as cache:
            out["impactqp compile"] = _timed_command(
                [python, "-m", "impactqp", "compile"], _env(cache, True))[1]
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.startup", description=__doc__)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--first-hour", action="store_true",
                        help="time the demo, a first frictional impact and `impactqp "
                             "compile`, each from an empty cache, instead")
    args = parser.parse_args(argv)
    if args.first_hour:
        runs = [first_hour(compile_all=i == 0) for i in range(args.repeats)]
        print(json.dumps({key: statistics.median(run[key] for run in runs if key in run)
                          for key in runs[0]}, indent=2))
        return 0
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
