"""Solves under a time limit: a child process that solves the tasks sent to it, one at a
time, and is killed when one overruns its limit (the solvers have no budget of their own).

A :class:`SolverProcess` lives across tasks, so a task costs two messages over a pipe, not a
process start, and a stop costs one fork. Where the caller may fork (POSIX, one thread: the
child inherits its compiled kernels) the child is forked from it; elsewhere (a Dask worker
runs threads, and forking a process with other threads may copy a lock one of them holds)
a fresh interpreter is spawned once, runs ``prepare``, and forks the solving children
itself, watching their limits. A task stopped at its limit, or whose reading and solving
took longer than it, is recorded as ``"time limit"`` by
:func:`~impactqp.io.collection.stopped_record`, never as a solve.
"""

from __future__ import annotations

import math
import multiprocessing
import threading
import time
from collections.abc import Callable
from multiprocessing.connection import Connection
from typing import Any

from .collection import Task, blank_record, failed_record, solve_task, stopped_record

__all__ = ["GRACE", "SolverProcess", "start_method"]

GRACE = 30.0
"""Seconds past a task's limit after which a spawned supervisor that has not answered is
killed with its task (it stops the task itself at the limit)."""


def start_method() -> str:
    """``"fork"`` where the platform forks and this process runs one thread, else
    ``"spawn"`` (forking a process with other threads may copy a lock one of them holds)."""
    forks = "fork" in multiprocessing.get_all_start_methods()
    return "fork" if forks and threading.active_count() == 1 else "spawn"


def _serve(conn: Connection, prepare: Callable[[], Any] | None) -> None:
    """A forked child: solve each task received until None."""
    if prepare is not None:
        prepare()
    conn.send(("ready", None))
    while (job := conn.recv()) is not None:
        task, _ = job
        try:
            record = solve_task(task, facts=lambda f: conn.send(("facts", f)))
        except BaseException as exc:  # noqa: BLE001 (a record, not the end of the child)
            record = failed_record(blank_record(task), exc)
        conn.send(("done", record))


def _supervise(conn: Connection, prepare: Callable[[], Any] | None) -> None:
    """A spawned child: prepare once, then run each task in a child forked from here."""
    if prepare is not None:
        prepare()
    inner = SolverProcess(method="fork")
    conn.send(("ready", None))
    try:
        while (job := conn.recv()) is not None:
            conn.send(("done", inner.run(*job)))
    except EOFError:  # the caller has gone
        pass
    finally:
        inner.close()


class SolverProcess:
    """A child process solving :class:`~impactqp.io.collection.Task` s under a time limit.

    Parameters
    ----------
    prepare : callable, optional
        Run by a spawned child before its first task (a forked one inherits the caller's
        state); picklable (a module-level function).
    method : str, optional
        The start method; default :func:`start_method`. With ``"spawn"`` the child is a
        supervisor that forks the solving children; this side then stops it only
        :data:`GRACE` seconds after a task's limit.
    """

    def __init__(self, prepare: Callable[[], Any] | None = None,
                 method: str | None = None) -> None:
        self.prepare = prepare
        self.context = multiprocessing.get_context(method or start_method())
        self.process: Any = None
        self.conn: Connection | None = None
        self.task: Task | None = None
        self.facts: dict[str, Any] | None = None
        self.deadline = self.started = 0.0
        self.limit = 0.0

    def _start(self) -> Connection:
        here, there = self.context.Pipe()
        forked = self.context.get_start_method() == "fork"
        self.process = self.context.Process(target=_serve if forked else _supervise,
                                            args=(there, None if forked else self.prepare),
                                            daemon=forked)  # a supervisor has children
        try:
            self.process.start()
        finally:
            there.close()
            if self.process.pid is None:  # it did not start: nothing to stop
                self.process = None
                here.close()
        if here.recv()[0] != "ready":  # EOFError when the child dies preparing
            raise RuntimeError("the solving process did not start")
        self.conn = here
        return here

    @property
    def busy(self) -> bool:
        return self.task is not None

    def submit(self, task: Task, limit: float) -> None:
        """Send ``task``, to end within ``limit`` seconds from now (reading its file too)."""
        conn = self.conn or self._start()
        self.task, self.facts, self.limit = task, None, limit
        self.started = time.perf_counter()
        spawned = self.context.get_start_method() != "fork"
        self.deadline = self.started + limit + (GRACE if spawned else 0.0)
        conn.send((task, limit))

    def collect(self, timeout: float | None = None) -> dict[str, Any] | None:
        """The busy task's record once it is done or overdue (the child then killed), or
        None when neither happens within ``timeout`` seconds (None: until one does)."""
        assert self.task is not None and self.conn is not None
        while True:
            left = self.deadline - time.perf_counter()
            wait = max(left, 0.0) if timeout is None else max(min(left, timeout), 0.0)
            try:
                message = self.conn.recv() if self.conn.poll(
                    None if math.isinf(wait) else wait) else None
            except EOFError:  # the child died (a crash of a library under the solver)
                return self._finish(failed_record(
                    stopped_record(self.task, self.facts, time.perf_counter() - self.started,
                                   self.limit),
                    RuntimeError(f"the solving process died (exit {self._stop()})")))
            if message is None:
                if time.perf_counter() < self.deadline:
                    return None
                seconds = time.perf_counter() - self.started
                self._stop()
                return self._finish(stopped_record(self.task, self.facts, seconds,
                                                   self.limit))
            kind, payload = message
            if kind == "facts":
                self.facts = payload
                continue
            return self._finish(payload)

    def _finish(self, record: dict[str, Any]) -> dict[str, Any]:
        """The busy task's record, as ``"time limit"`` when reading and solving took longer
        than the limit (the answer came back before this side saw the deadline pass)."""
        task, self.task = self.task, None
        spent = (record.get("read_seconds") or 0.0) + (record.get("seconds") or 0.0)
        if record["status"] != "time limit" and spent > self.limit:
            assert task is not None
            return stopped_record(task, record, spent, self.limit)
        return record

    def run(self, task: Task, limit: float) -> dict[str, Any]:
        """``task``'s record: solved within ``limit`` seconds, or stopped."""
        self.submit(task, limit)
        record = self.collect()
        assert record is not None
        return record

    def _stop(self) -> int | None:
        """Kill the child; its exit code. The next task starts another."""
        if self.process is not None:
            self.process.kill()
            self.process.join()
        code = None if self.process is None else self.process.exitcode
        if self.conn is not None:
            self.conn.close()
        self.process = self.conn = None
        return code

    def close(self) -> None:
        """End the child (asked to stop between tasks, killed otherwise)."""
        if self.conn is not None and self.task is None:
            try:
                self.conn.send(None)
                self.process.join(timeout=5)
            except (OSError, ValueError):
                pass
        self._stop()
