"""``python -m benchmarks.collection_scaling [--problems 200] [--workers 2]``: one collection
of the repository's friction problems, copied round-robin under distinct names, run in this
process, then on a Dask ``LocalCluster`` of one worker and of ``--workers`` workers (one
thread each, separate processes), all in one run; prints the times, the speed-up and whether
the records agree (status, route, iterations; ABH error and ‖r‖ to 1e-9 relative).

The workers compile their kernels before the timer (:func:`impactqp.collection.prepare_worker`,
timed apart); the load of the machine (``os.getloadavg``) is printed beside the times.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

from impactqp.collection import prepare_worker, run_collection

from .friction_data import FILES

#: the suite's problems that read and solve in a few ms to half a second each (KaplasTower,
#: ~1.3 s, and Spheres, ~3 s to read and reduce its global form, are left out to keep the
#: run short)
NAMES = ("LMGC-00046", "NESpheres-10", "BoxesStack1", "PerioBox", "Box_Stacks",
         "spheres-in-a-box", "Capsules")
SAME = ("status", "error_name", "backend", "iterations", "contacts")


def make_collection(folder: Path, problems: int) -> None:
    """``problems`` files in ``folder``: the files of :data:`NAMES` in turn, numbered."""
    for i in range(problems):
        source = FILES[NAMES[i % len(NAMES)]]
        shutil.copyfile(source, folder / f"{i:04d}-{source.name}")


def agree(a: list[dict], b: list[dict]) -> bool:
    """Same outcome, route and answer (to 1e-9 relative) on every record."""
    def close(x: float | None, y: float | None) -> bool:
        return (x is None and y is None) or (x is not None and y is not None
                                             and abs(x - y) <= 1e-9 * abs(x) + 1e-300)
    return len(a) == len(b) and all(
        all(x[k] == y[k] for k in SAME) and close(x["abh_error"], y["abh_error"])
        and close(x["r_norm"], y["r_norm"]) for x, y in zip(a, b, strict=True))


def _spent(records: list[dict]) -> str:
    """The seconds the records say were spent reading and solving, summed."""
    read = sum(r["read_seconds"] or 0.0 for r in records)
    solve = sum(r["seconds"] or 0.0 for r in records)
    cpu = sum(r["cpu_seconds"] or 0.0 for r in records)
    return (f"reading {read:.1f} s, solving {solve:.1f} s of which {cpu:.1f} s on a processor "
            f"({cpu / solve:.0%})")


def on_cluster(folder: Path, output: Path, workers: int) -> tuple[list[dict], float, float]:
    """Records, seconds of the run and seconds of the workers' warm-up on a LocalCluster."""
    import distributed

    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        t0 = time.perf_counter()
        client.run(prepare_worker)
        warm = time.perf_counter() - t0
        t0 = time.perf_counter()
        run = run_collection(folder, output, client=client)
        return run.records, time.perf_counter() - t0, warm


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.collection_scaling")
    parser.add_argument("--problems", type=int, default=200)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--no-local", action="store_true", help="skip the in-process run")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp) / "collection"
        folder.mkdir()
        make_collection(folder, args.problems)
        print(f"{args.problems} problems; load average before: {os.getloadavg()}")
        local = None
        if not args.no_local:
            prepare_worker()
            t0 = time.perf_counter()
            local = run_collection(folder, Path(tmp) / "local.jsonl").records
            print(f"in this process: {time.perf_counter() - t0:.1f} s ({_spent(local)})")
        one, t1, w1 = on_cluster(folder, Path(tmp) / "one.jsonl", 1)
        print(f"1 worker: {t1:.1f} s (warm-up {w1:.1f} s; {_spent(one)}); load "
              f"{os.getloadavg()}")
        many, tn, wn = on_cluster(folder, Path(tmp) / "many.jsonl", args.workers)
        print(f"{args.workers} workers: {tn:.1f} s (warm-up {wn:.1f} s; {_spent(many)}); load "
              f"{os.getloadavg()}")
        for name in NAMES:  # where the time went: mean solve per source file
            source = FILES[name].name
            mean = [sum(r["seconds"] for r in recs if r["file"].endswith(source))
                    / sum(r["file"].endswith(source) for r in recs) for recs in (one, many)]
            print(f"  {name}: {mean[0] * 1e3:.1f} ms on 1 worker, {mean[1] * 1e3:.1f} ms on "
                  f"{args.workers}")
        certified = sum(r["status"] == "certified" for r in many)
        print(f"speed-up {t1 / tn:.2f}x; certified {certified} of {len(many)}; records agree "
              f"(1 vs {args.workers} workers): {agree(one, many)}"
              + ("" if local is None else f", (local vs {args.workers} workers): "
                 f"{agree(local, many)}"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
