"""Certified 3-ball Moreau impacts per second of ``iq.moreau_batch``, fresh results against
results written into the previous call's arrays (``out=``), and optionally against another
checkout of impactqp in the same period.

``python -m benchmarks.batch_rates [--rows 1e6 1e7] [--repeats 7] [--rounds 2]
[--against DIR]``

Each (checkout, way, rows) runs in a process of its own (the rows of the batch benchmark,
:func:`benchmarks.families.BUILDERS` ``"batch"``), warmed up by one untimed call, then timed
call by call: processor time (user + system, from ``resource.getrusage``, which a loaded
machine disturbs far less than the clock), wall time and minor page faults. The rounds
alternate the checkouts so that both see the same load; the load average is printed beside.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

CHILD = r"""
import inspect, json, resource, sys, time
import numpy as np
import impactqp as iq
from benchmarks.families import BUILDERS
k, way, repeats = int(float(sys.argv[1])), sys.argv[2], int(sys.argv[3])
if way == "out" and "out" not in inspect.signature(iq.moreau_batch).parameters:
    print(json.dumps(None)); sys.exit()
case = BUILDERS["batch"](k, 0)
p, U = case.problem, case.U
last = iq.moreau_batch(p, U)
if way == "fresh":
    del last
cpu, wall, faults = [], [], []
for _ in range(repeats):
    a, t = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
    if way == "out":
        last = iq.moreau_batch(p, U, out=last)
    else:
        r = iq.moreau_batch(p, U)
    t, b = time.perf_counter() - t, resource.getrusage(resource.RUSAGE_SELF)
    if way == "fresh":
        del r
    cpu.append(b.ru_utime + b.ru_stime - a.ru_utime - a.ru_stime)
    wall.append(t)
    faults.append(b.ru_minflt - a.ru_minflt)
print(json.dumps({"cpu": cpu, "wall": wall, "faults": faults,
                  "load": open("/proc/loadavg").read().split()[0]}))
"""


def measure(root: Path, k: int, way: str, repeats: int) -> dict | None:
    """One process of the checkout at ``root``: the timings of ``repeats`` calls, or None
    when that checkout has no ``out=``."""
    here = Path(__file__).resolve().parent.parent
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), str(here)]))
    done = subprocess.run([sys.executable, "-c", CHILD, str(k), way, str(repeats)], env=env,
                          cwd=root, capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def line(label: str, k: int, way: str, runs: list[dict]) -> str:
    """A table row: medians and bests over every call of ``runs``."""
    cpu = sorted(t for r in runs for t in r["cpu"])
    wall = sorted(t for r in runs for t in r["wall"])
    faults = sorted(f for r in runs for f in r["faults"])
    med = len(cpu) // 2
    loads = ", ".join(r["load"] for r in runs)
    return (f"| {label} | {way} | {k:.0e} | {cpu[med]:.3f} / {cpu[0]:.3f} s | "
            f"{k / cpu[med]:.3g} / {k / cpu[0]:.3g} | {wall[med]:.3f} / {wall[0]:.3f} s | "
            f"{k / wall[med]:.3g} / {k / wall[0]:.3g} | {faults[len(faults) // 2]} | {loads} |")


def main(argv: list[str] | None = None) -> int:
    """Run the rounds and print the table (markdown)."""
    parser = argparse.ArgumentParser(prog="python -m benchmarks.batch_rates",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--rows", type=float, nargs="+", default=[1e6, 1e7])
    parser.add_argument("--repeats", type=int, default=7, help="timed calls per process")
    parser.add_argument("--rounds", type=int, default=2, help="processes per configuration")
    parser.add_argument("--against", type=Path, help="another checkout, e.g. of main")
    args = parser.parse_args(argv)
    here = Path(__file__).resolve().parent.parent
    roots = [("this", here)] + ([("against", args.against.resolve())] if args.against else [])
    print("| checkout | way | rows | CPU median / best | impacts/s by CPU | wall median / best "
          "| impacts/s by wall | minor faults a call | load (1 min) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for k in (int(r) for r in args.rows):
        runs: dict[tuple[str, str], list[dict]] = {}
        for _ in range(args.rounds):
            for label, root in roots:
                for way in ("fresh", "out"):
                    result = measure(root, k, way, args.repeats)
                    if result is not None:
                        runs.setdefault((label, way), []).append(result)
        for (label, way), found in runs.items():
            print(line(label, k, way, found), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
