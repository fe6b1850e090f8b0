"""Solves under a time limit: a child process that solves the tasks sent to it, one at a
time, and is killed when one overruns its limit (the solvers have no budget of their own).

A :class:`SolverProcess` lives across tasks, so a task costs two messages over a pipe, not a
process start, and a stop costs one fork. Where the caller may fork (POSIX, one thread: the
child inherits its compiled kernels) the child is forked from it. Elsewhere — a Dask worker
runs threads (forking a process with other threads may copy a lock one of them holds) and
is a daemon (which :mod:`multiprocessing` forbids to have children) — a fresh interpreter is
started once as a plain subprocess, runs ``prepare``, and forks the solving children itself,
watching their limits. A task stopped at its limit, or whose reading and solving took
longer than it, is recorded as ``"time limit"`` by
:func:`~impactqp.io.collection.stopped_record`, never as a solve.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import socket
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from multiprocessing.connection import Connection
from typing import Any

from .collection import Task, blank_record, failed_record, solve_task, stopped_record

__all__ = ["GRACE", "SolverProcess", "start_method", "supervise"]

GRACE = 30.0
"""Seconds past a task's limit after which a supervisor that has not answered is killed
with its task (it stops the task itself at the limit)."""


def start_method() -> str:
    """``"fork"`` where this process may fork a solving child itself (POSIX, one thread,
    not a daemon), else ``"supervisor"``: a subprocess that forks them."""
    daemon = multiprocessing.current_process().daemon
    forks = "fork" in multiprocessing.get_all_start_methods()
    return "fork" if forks and not daemon and threading.active_count() == 1 else "supervisor"


def _serve(conn: Connection) -> None:
    """A forked child: solve each task received until None or the caller's end."""
    conn.send(("ready", None))
    try:
        while (job := conn.recv()) is not None:
            task, _ = job
            try:
                record = solve_task(task, facts=lambda f: conn.send(("facts", f)))
            except BaseException as exc:  # noqa: BLE001 (a record, not the end of the child)
                record = failed_record(blank_record(task), exc)
            conn.send(("done", record))
    except (EOFError, BrokenPipeError):  # the caller has gone
        pass


def supervise(fd: int) -> None:
    """The supervisor subprocess, on the socket ``fd``: receive ``prepare`` and run it, then
    run each task in a child forked from here, until None or the caller's end."""
    conn = Connection(fd)
    prepare = conn.recv()
    if prepare is not None:
        prepare()
    inner = SolverProcess(method="fork")
    conn.send(("ready", None))
    try:
        while (job := conn.recv()) is not None:
            conn.send(("done", inner.run(*job)))
    except (EOFError, BrokenPipeError):  # the caller has gone
        pass
    finally:
        inner.close()


class SolverProcess:
    """A child process solving :class:`~impactqp.io.collection.Task` s under a time limit.

    Parameters
    ----------
    prepare : callable, optional
        Run by a supervisor before its first task (a forked child inherits the caller's
        state instead); picklable (a module-level function).
    method : {"fork", "supervisor"}, optional
        Default :func:`start_method`. A supervisor forks the solving children and stops
        them at their limits; this side stops it only :data:`GRACE` seconds after one.
    """

    def __init__(self, prepare: Callable[[], Any] | None = None,
                 method: str | None = None) -> None:
        self.prepare = prepare
        self.forked = (method or start_method()) == "fork"
        self.process: Any = None
        self.conn: Connection | None = None
        self.task: Task | None = None
        self.facts: dict[str, Any] | None = None
        self.deadline = self.started = 0.0
        self.limit = 0.0

    def _start(self) -> Connection:
        if self.forked:
            context = multiprocessing.get_context("fork")
            here, there = context.Pipe()
            process = context.Process(target=_serve, args=(there,), daemon=True)
            try:
                process.start()
            finally:
                there.close()
        else:
            mine, theirs = socket.socketpair()
            code = f"from {__name__} import supervise; supervise({theirs.fileno()})"
            env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
            try:  # the interpreter's own path, as multiprocessing's spawn gives it
                process = subprocess.Popen([sys.executable, "-c", code],
                                           pass_fds=[theirs.fileno()], env=env)
            finally:
                theirs.close()
            here = Connection(mine.detach())
            here.send(self.prepare)
        self.process = process
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
        self.deadline = self.started + limit + (0.0 if self.forked else GRACE)
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
        if record["status"] in ("certified", "not certified") and spent > self.limit:
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
        code = None
        if self.process is not None:
            self.process.kill()
            if self.forked:
                self.process.join()
                code = self.process.exitcode
            else:
                code = self.process.wait()
        if self.conn is not None:
            self.conn.close()
        self.process = self.conn = None
        return code

    def close(self) -> None:
        """End the child (asked to stop between tasks, killed otherwise)."""
        if self.conn is not None and self.task is None:
            try:
                self.conn.send(None)
                if self.forked:
                    self.process.join(timeout=5)
                else:
                    self.process.wait(timeout=5)
            except (OSError, ValueError, subprocess.TimeoutExpired):
                pass
        self._stop()
