"""Whole collections of frictional contact problems: every FCLib or Siconos file of a folder
solved by impactqp's friction methods, in this process, on local processes or on a Dask
cluster, each outcome a record appended to a JSON Lines file as it arrives.

:func:`run_collection` is resumable: run again with the same output, it skips the (file,
method) pairs already recorded, so a crash loses at most the problems being solved at that
moment. Workers compile the friction kernels (:mod:`impactqp.precompile`) once, before
their first problem. A time limit is kept by solving in child processes that are killed at
the limit (:mod:`impactqp.io.deadline`): such a problem is recorded as ``"time limit"``.
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from multiprocessing.connection import wait
from pathlib import Path
from typing import Any

from .base.arrays import as_count, check_tol
from .base.checks import FRICTION_TOL
from .errors import InputError
from .io.collection import (
    STATUSES,
    Task,
    blank_record,
    check_methods,
    collection_files,
    failed_record,
    solve_task,
)
from .io.deadline import SolverProcess
from .io.journal import Journal
from .kernels.first_calls import compiling
from .precompile import STAGES

__all__ = ["CollectionRun", "run_collection", "prepare_worker"]

Record = dict[str, Any]


def prepare_worker() -> None:
    """Compile the friction kernels, or load them from the cache: the friction stage of
    :func:`impactqp.precompile.compile_kernels` (compiled, not run as their Python text as
    a process's first small calls may be), run by each worker before its first problem."""
    with compiling():
        dict(STAGES)["friction"]()


@dataclass(frozen=True)
class CollectionRun:
    """What :func:`run_collection` did.

    Attributes
    ----------
    records : list of dict
        One record per (file, method) of the collection, in the order of the files then
        the methods (see :func:`impactqp.io.collection.solve_task` for the fields).
    new : int
        Records this call solved and wrote.
    skipped : int
        (file, method) pairs found in the output already, not solved again.
    seconds : float
        Wall-clock time of this call.
    output : Path
        The JSON Lines file.
    """

    records: list[Record]
    new: int
    skipped: int
    seconds: float
    output: Path

    def counts(self) -> dict[str, dict[str, int]]:
        """Per method, the number of records of each status (:data:`STATUSES`)."""
        out: dict[str, dict[str, int]] = {}
        for r in self.records:
            out.setdefault(r["method"], dict.fromkeys(STATUSES, 0))[r["status"]] += 1
        return out


def run_collection(folder: str | Path, output: str | Path, *,
                   methods: str | Sequence[str] = ("auto",), time_limit: float | None = None,
                   tol: float = FRICTION_TOL, n_jobs: int = 1, scheduler: str | None = None,
                   client: Any = None,
                   on_record: Callable[[Record], None] | None = None) -> CollectionRun:
    """Solve every problem file of ``folder`` with each of ``methods``, recording each outcome
    in ``output`` as it arrives.

    Parameters
    ----------
    folder : str or Path
        Its FCLib (``.hdf5``, ``.h5``) and Siconos (``.dat``, ``.dat.gz``) files, subfolders
        included (:func:`impactqp.io.collection.collection_files`).
    output : str or Path
        JSON Lines file of the records; the pairs it records already are skipped.
    methods : str or sequence of str
        ``backend=`` of :func:`impactqp.solve_friction`: ``"auto"`` (the default route) and/or
        named methods (``impactqp.friction.FRICTION_BACKENDS``).
    time_limit : float, optional
        Seconds each problem may take, reading its file included; a problem over it is
        stopped and recorded as ``"time limit"``. The solves then run in child processes
        (one per worker, replaced after a stop).
    tol : float
        The certificate's tolerance (ABH error).
    n_jobs : int
        Local worker processes (1 and no time limit: solved in this process).
    scheduler : str, optional
        Address of a dask.distributed scheduler to run on (the ``dask`` extra); its workers
        read the files at ``folder``'s path (a filesystem they share).
    client : dask.distributed.Client, optional
        A client to run on, instead of ``scheduler``.
    on_record : callable, optional
        Called with each new record once it is written.

    Returns
    -------
    CollectionRun

    Raises
    ------
    InputError
        ``folder`` is not a folder, ``output`` is not a regular file, a method is unknown,
        ``time_limit`` is not a positive number, ``tol`` is not a tolerance, or both
        ``scheduler`` and ``client``.
    ProblemFileError
        ``output`` holds a damaged line before its last one.
    """
    start = time.perf_counter()
    names = check_methods(methods)
    limit = _check_limit(time_limit)
    tol = check_tol(tol)
    n_jobs = as_count("n_jobs", n_jobs, minimum=1)
    if scheduler is not None and client is not None:
        raise InputError("give a scheduler address or a client, not both")
    journal = Journal(output)
    files = collection_files(folder)
    tasks = [Task(str(folder), f, m, tol) for f in files for m in names]
    done = {(r.get("file"), r.get("method")) for r in journal.records()}
    todo = [t for t in tasks if t.key not in done]

    def emit(record: Record) -> None:
        journal.append(record)
        if on_record is not None:
            on_record(record)

    if todo and (scheduler is not None or client is not None):
        _run_dask(todo, limit, emit, scheduler, client)
    elif todo:
        _run_local(todo, limit, n_jobs, emit)
    latest = {(r.get("file"), r.get("method")): r for r in journal.records()}
    return CollectionRun([latest[t.key] for t in tasks], len(todo), len(tasks) - len(todo),
                         time.perf_counter() - start, journal.path)


def _check_limit(time_limit: Any) -> float | None:
    if time_limit is None:
        return None
    try:
        value = float(time_limit)
    except (TypeError, ValueError):
        value = math.nan
    if not value > 0 or isinstance(time_limit, bool):
        raise InputError(f"time_limit must be a positive number of seconds, got {time_limit!r}")
    return value


def _run_local(tasks: list[Task], limit: float | None, n_jobs: int,
               emit: Callable[[Record], None]) -> None:
    """In this process (one job, no limit), else on ``n_jobs`` child processes fed one task
    at a time: each sent to the first free child, each child watched against its limit."""
    prepare_worker()  # here: children forked from this process inherit the kernels
    if n_jobs == 1 and limit is None:
        for task in tasks:
            emit(solve_task(task))
        return
    pending = deque(tasks)
    pool = [SolverProcess(prepare_worker) for _ in range(min(n_jobs, len(tasks)))]
    try:
        while pending or any(p.busy for p in pool):
            for proc in pool:
                if not proc.busy and pending:
                    proc.submit(pending.popleft(), math.inf if limit is None else limit)
            busy = [p for p in pool if p.busy]
            soonest = min(p.deadline for p in busy) - time.perf_counter()
            wait([p.conn for p in busy], None if math.isinf(soonest) else max(soonest, 0.0))
            for proc in busy:
                record = proc.collect(timeout=0.0)
                if record is not None:
                    emit(record)
    finally:
        for proc in pool:
            proc.close()


GROUP = 4
"""Problems per Dask task at most. Each task costs milliseconds of the client's, the
scheduler's and its worker's processors and a hand-over between them (measured: ~2.5 ms of
the scheduler's, ~2 ms of the worker's, a 7–11 ms gap between a worker's tasks on a busy
machine); a few problems per task share them, while every worker still gets many tasks.
Groups of 4 cut the scheduler's processor time by 25–30 % on a 100-problem collection."""


def _groups(tasks: list[Task], workers: int) -> list[list[Task]]:
    """``tasks`` in groups of up to :data:`GROUP` (at least 8 groups per worker), the largest
    files first: as far as a file's size tells its solve's length, the long solves start
    early and the workers end together."""
    size = max(1, min(GROUP, len(tasks) // (8 * max(workers, 1))))
    ordered = sorted(tasks, key=lambda t: -_size(t))  # stable: ties keep their order
    return [ordered[i:i + size] for i in range(0, len(ordered), size)]


def _size(task: Task) -> int:
    """Bytes of ``task``'s file (0 when it cannot be read: its solve records why)."""
    try:
        return (Path(task.folder) / task.file).stat().st_size
    except OSError:
        return 0


def _run_dask(tasks: list[Task], limit: float | None, emit: Callable[[Record], None],
              scheduler: str | None, client: Any) -> None:
    """One Dask task per group of problems (:func:`_groups`); records written as the groups
    end. A group whose worker died is run again one problem per task, so that a problem
    that kills its worker fails alone."""
    try:
        import distributed
    except ImportError as exc:
        from .errors import OptionalDependencyError

        raise OptionalDependencyError("running on a Dask cluster needs the dask extra: "
                                      "pip install 'impactqp[dask]'") from exc
    own = distributed.Client(scheduler) if client is None else None
    client = client or own
    try:
        client.run(_prepare_once)  # the workers there now; later ones prepare on first task
        workers = len(client.scheduler_info().get("workers", {}))
        futures = {client.submit(_solve_group, group, limit, pure=False): group
                   for group in _groups(tasks, workers)}
        arrived = distributed.as_completed(futures)
        try:
            for future in arrived:
                group = futures[future]
                try:
                    records = future.result()
                except Exception as exc:  # the worker died with it (Dask gave up retrying)
                    if len(group) > 1:
                        for task in group:
                            alone = client.submit(_solve_group, [task], limit, pure=False)
                            futures[alone] = [task]
                            arrived.add(alone)
                        continue
                    records = [failed_record(blank_record(group[0]), exc)]
                for record in records:
                    emit(record)
        finally:
            client.cancel(list(futures))
            client.run(_close_solvers)
    finally:
        if own is not None:
            own.close()


_PREPARED = threading.Event()
_SOLVERS: dict[int, SolverProcess] = {}
_LOCK = threading.Lock()


def _prepare_once() -> None:
    with _LOCK:
        if not _PREPARED.is_set():
            prepare_worker()
            _PREPARED.set()


def _solve_group(tasks: list[Task], limit: float | None) -> list[Record]:
    """A Dask worker's solves, one after the other: in its own process, or in a child process
    per worker thread under a time limit."""
    _prepare_once()
    if limit is None:
        return [solve_task(task) for task in tasks]
    with _LOCK:
        proc = _SOLVERS.setdefault(threading.get_ident(), SolverProcess(prepare_worker))
    return [proc.run(task, limit) for task in tasks]


def _close_solvers() -> None:
    with _LOCK:
        for proc in _SOLVERS.values():
            proc.close()
        _SOLVERS.clear()
