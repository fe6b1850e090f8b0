"""``python -m benchmarks.collection_scaling [--problems 200] [--workers 2]``: one collection
of the repository's friction problems, copied round-robin under distinct names, run in this
process, then on a Dask ``LocalCluster`` of one worker and of ``--workers`` workers (one
thread each, separate processes), all in one run; prints the times, the speed-up and whether
the records agree (status, route, iterations; ABH error and ‖r‖ to 1e-9 relative).

The workers compile their kernels before the timer (:func:`impactqp.collection.prepare_worker`,
timed apart); the load of the machine (``os.getloadavg``) is printed beside the times. On a
busy machine the clock times say more of the other processes than of the run, so each run
also reports the processor time of every worker and of this process (the client and the
LocalCluster's scheduler), how much of the run the workers spent in tasks (Dask's task
stream) and the gaps between their tasks, and an estimate of its time on idle cores
(:meth:`ClusterRun.idle_cores`); the speed-up is printed both ways, the estimate labelled so.
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import shutil
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

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


def cpu_seconds() -> float:
    """Processor seconds (user and system) this process has used so far: run on each worker
    before and after a run."""
    use = resource.getrusage(resource.RUSAGE_SELF)
    return use.ru_utime + use.ru_stime


IDLE = 3.0
"""Seconds the cluster is watched idle before a run: the processor time its processes spend
per second doing nothing (heartbeats, monitors) is counted apart from the run's work."""


@dataclass(frozen=True)
class ClusterRun:
    """One run on a LocalCluster: its records and where its time went."""

    records: list[dict]
    seconds: float
    warm_up: float
    worker_cpu: list[float]
    """Processor seconds of each worker process during the run."""
    client_cpu: float
    """Processor seconds of this process (the client and the LocalCluster's scheduler)."""
    idle_rates: list[float]
    """Processor seconds per second of each worker, then of this process, while idle."""
    busy: list[float]
    """Seconds each worker spent running tasks (Dask's task stream)."""
    gaps: list[float]
    """Seconds between the end of a task and the start of the next one on the same worker."""

    def idle_cores(self, cores: int) -> float:
        """The run's seconds on ``cores`` idle processors, estimated from its processor time.

        Each process' work is its processor time less its idle rate times the run's length
        (what it spends per second whatever it does). The larger of: the workers' work
        shared evenly among them (they take tasks as they free up), each on the part of a
        core its idle rate leaves; all the processes' work on the cores their idle rates
        leave. Not counted: waiting for a processor, the gaps between tasks, the last
        task's tail, the solves' own processor time growing when both cores are busy.
        """
        rates, client_rate = self.idle_rates[:-1], self.idle_rates[-1]
        work = [max(c - r * self.seconds, 0.0) for c, r in zip(self.worker_cpu, rates,
                                                                strict=True)]
        client = max(self.client_cpu - client_rate * self.seconds, 0.0)
        n = len(work)
        shared = sum(work) / (n * (1.0 - sum(rates) / n))
        return max(shared, (sum(work) + client) / (cores - sum(rates) - client_rate))

    def describe(self, cores: int) -> str:
        cpu = ", ".join(f"{c:.1f}" for c in self.worker_cpu)
        rates = ", ".join(f"{r * 1e3:.0f}" for r in self.idle_rates)
        busy = ", ".join(f"{b / self.seconds:.0%}" for b in self.busy)
        gap = float(np.median(self.gaps)) * 1e3 if self.gaps else math.nan
        return (f"{self.seconds:.1f} s (warm-up {self.warm_up:.1f} s; {_spent(self.records)}); "
                f"workers' processor time {cpu} s, this process' (client, scheduler) "
                f"{self.client_cpu:.1f} s (idle: {rates} ms/s); workers busy {busy} of the run, "
                f"median gap between tasks {gap:.1f} ms; on {cores} idle cores "
                f"~{self.idle_cores(cores):.1f} s (estimate)")


def on_cluster(folder: Path, output: Path, workers: int) -> ClusterRun:
    """Run the collection on a LocalCluster of ``workers`` one-thread worker processes."""
    import distributed

    with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        t0 = time.perf_counter()
        client.run(prepare_worker)
        warm = time.perf_counter() - t0
        before, mine, t0 = client.run(cpu_seconds), time.process_time(), time.perf_counter()
        time.sleep(IDLE)
        after, mine, idle = (client.run(cpu_seconds), time.process_time() - mine,
                             time.perf_counter() - t0)
        rates = [(after[w] - before[w]) / idle for w in sorted(after)] + [mine / idle]
        before = client.run(cpu_seconds)
        mine = time.process_time()
        t0 = time.perf_counter()
        with distributed.get_task_stream(client) as stream:
            run = run_collection(folder, output, client=client)
        seconds = time.perf_counter() - t0
        mine = time.process_time() - mine
        after = client.run(cpu_seconds)
    spans: dict[str, list[tuple[float, float]]] = {}
    for task in stream.data:
        for span in task["startstops"]:
            if span["action"] == "compute":
                spans.setdefault(task["worker"], []).append((span["start"], span["stop"]))
    gaps = [b[0] - a[1] for s in spans.values() for a, b in zip(sorted(s), sorted(s)[1:])]
    return ClusterRun(run.records, seconds, warm, [after[w] - before[w] for w in sorted(after)],
                      mine, rates, [sum(b - a for a, b in s) for s in spans.values()], gaps)


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
            t0, cpu = time.perf_counter(), time.process_time()
            local = run_collection(folder, Path(tmp) / "local.jsonl").records
            print(f"in this process: {time.perf_counter() - t0:.1f} s, "
                  f"{time.process_time() - cpu:.1f} s on a processor ({_spent(local)})")
        cores = os.cpu_count() or 1
        one = on_cluster(folder, Path(tmp) / "one.jsonl", 1)
        print(f"1 worker: {one.describe(cores)}; load {os.getloadavg()}")
        many = on_cluster(folder, Path(tmp) / "many.jsonl", args.workers)
        print(f"{args.workers} workers: {many.describe(cores)}; load {os.getloadavg()}")
        for name in NAMES:  # where the time went: mean solve per source file
            source = FILES[name].name
            mean = [sum(r["seconds"] for r in recs if r["file"].endswith(source))
                    / sum(r["file"].endswith(source) for r in recs)
                    for recs in (one.records, many.records)]
            print(f"  {name}: {mean[0] * 1e3:.1f} ms on 1 worker, {mean[1] * 1e3:.1f} ms on "
                  f"{args.workers}")
        certified = sum(r["status"] == "certified" for r in many.records)
        print(f"speed-up {one.seconds / many.seconds:.2f}x (wall clock; "
              f"{one.idle_cores(cores) / many.idle_cores(cores):.2f}x estimated on {cores} idle "
              f"cores from the processor times); certified {certified} of {len(many.records)}; "
              f"records agree (1 vs {args.workers} workers): {agree(one.records, many.records)}"
              + ("" if local is None else f", (local vs {args.workers} workers): "
                 f"{agree(local, many.records)}"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
