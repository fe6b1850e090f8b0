"""The problems of a collection and the record of one solve: a folder of FCLib HDF5 files
and Siconos text files, each read by :func:`~impactqp.io.fclib.load_fclib` and solved by
:func:`~impactqp.laws.friction.solve_friction` with one method, its outcome kept as a plain
dictionary that a JSON line holds (:mod:`impactqp.io.journal`).

Every outcome is a record, never an exception: ``"certified"`` (the answer passed its
certificate, docs/theory.md §15), ``"not certified"`` (a
:class:`~impactqp.errors.CertificateError`, with the ABH error of the best answer it
carries), ``"time limit"`` (stopped, see :mod:`impactqp.io.deadline`) or ``"error"`` (any
other exception, by its class name: a damaged file is a ``ProblemFileError``).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from ..errors import CertificateError, InputError
from ..laws.friction import FRICTION_BACKENDS, solve_friction
from .fclib import load_fclib

__all__ = ["SUFFIXES", "STATUSES", "Task", "collection_files", "solve_task", "stopped_record",
           "failed_record",
           "blank_record", "FACTS"]

SUFFIXES = (".hdf5", ".h5", ".dat", ".dat.gz")
"""The file names of a collection: FCLib HDF5 and Siconos text, plain or gzip-compressed."""
STATUSES = ("certified", "not certified", "time limit", "error")
"""What a record's ``status`` says."""
FACTS = ("contacts", "d", "mu_min", "mu_max", "read_seconds")
"""The fields of a record known once its file is read, before the solve."""


class Task(NamedTuple):
    """One problem file solved by one method.

    Attributes
    ----------
    folder : str
        The collection's folder.
    file : str
        The file, relative to ``folder`` (``/``-separated): with ``method``, the record's key.
    method : str
        ``backend=`` of :func:`~impactqp.laws.friction.solve_friction` (``"auto"``: the
        default route).
    tol : float
        The certificate's tolerance.
    """

    folder: str
    file: str
    method: str
    tol: float

    @property
    def key(self) -> tuple[str, str]:
        return self.file, self.method


def collection_files(folder: str | Path) -> list[str]:
    """The problem files under ``folder`` (its subfolders too), by :data:`SUFFIXES`, as
    sorted ``/``-separated paths relative to it.

    Raises
    ------
    InputError
        ``folder`` is not a folder.
    """
    root = Path(folder)
    if not root.is_dir():
        raise InputError(f"the collection {folder} is not a folder")
    return sorted(p.relative_to(root).as_posix() for p in root.rglob("*")
                  if p.name.lower().endswith(SUFFIXES) and p.is_file())


def check_methods(methods: Any) -> tuple[str, ...]:
    """``methods`` as a tuple of names of :data:`FRICTION_BACKENDS`, at least one, no repeat.

    Raises
    ------
    InputError
        An empty sequence, a repeated name or one that is not a friction method.
    """
    names = (methods,) if isinstance(methods, str) else tuple(methods)
    unknown = [m for m in names if m not in FRICTION_BACKENDS]
    if not names or unknown or len(set(names)) != len(names):
        raise InputError(f"methods must be distinct names among {list(FRICTION_BACKENDS)}, "
                         f"got {list(names)}")
    return names


def solve_task(task: Task, facts: Any = None) -> dict[str, Any]:
    """Read ``task``'s file and solve it: its record (every outcome, not an exception).

    Parameters
    ----------
    task : Task
    facts : callable, optional
        Called with the record so far (:data:`FACTS` filled) once the file is read, before
        it is solved (a watching process learns them so).

    Returns
    -------
    dict
        ``file``, ``method``, ``status`` (:data:`STATUSES`), ``error_name``, ``message``,
        ``contacts``, ``d``, ``mu_min``, ``mu_max``, ``read_seconds``, ``seconds`` (of the
        solve, wall clock), ``cpu_seconds`` (the solving thread's processor time: less than
        ``seconds`` when the machine was busy), ``iterations``, ``abh_error``, ``backend``
        (the method that answered), ``r_norm`` (‖r‖₂ of the answer), ``tol``.
    """
    record = blank_record(task)
    start = time.perf_counter()
    try:
        problem = load_fclib(Path(task.folder) / task.file)
    except Exception as exc:  # a damaged file is a record, the run goes on
        return failed_record(record, exc)
    mu = np.asarray(problem.mu, dtype=float)
    record.update(contacts=int(problem.n_contacts), d=int(problem.contact_dim),
                  mu_min=float(mu.min(initial=np.inf)) if mu.size else None,
                  mu_max=float(mu.max(initial=-np.inf)) if mu.size else None,
                  read_seconds=time.perf_counter() - start)
    if facts is not None:
        facts(dict(record))
    start, cpu = time.perf_counter(), time.thread_time()
    try:
        result = solve_friction(problem, backend=task.method, tol=task.tol)
    except CertificateError as exc:
        record.update(status="not certified", error_name=type(exc).__name__,
                      message=str(exc), seconds=time.perf_counter() - start,
                      cpu_seconds=time.thread_time() - cpu)
        if exc.best is not None:
            record.update(_answer(exc.best))
        return record
    except Exception as exc:
        record["seconds"] = time.perf_counter() - start
        return failed_record(record, exc)
    record.update(status="certified", message="", seconds=result.solve_time,
                  cpu_seconds=time.thread_time() - cpu, **_answer(result))
    return record


def _answer(result: Any) -> dict[str, Any]:
    return {"iterations": int(result.iterations), "abh_error": float(result.error),
            "backend": result.backend, "r_norm": float(np.linalg.norm(result.r))}


def blank_record(task: Task) -> dict[str, Any]:
    """The record of ``task`` before anything is known of it (every field, None)."""
    return {"file": task.file, "method": task.method, "status": None, "error_name": None,
            "message": "", "contacts": None, "d": None, "mu_min": None, "mu_max": None,
            "read_seconds": None, "seconds": None, "cpu_seconds": None, "iterations": None,
            "abh_error": None,
            "backend": None, "r_norm": None, "tol": task.tol}


def failed_record(record: dict[str, Any], exc: BaseException) -> dict[str, Any]:
    """``record`` with status ``"error"``, the exception's class name and its message."""
    record.update(status="error", error_name=type(exc).__name__, message=str(exc)[:500])
    return record


def stopped_record(task: Task, facts: dict[str, Any] | None, seconds: float,
                   limit: float) -> dict[str, Any]:
    """The record of ``task`` stopped after ``seconds`` (at least its ``limit``), with the
    problem's facts where its file was read before the stop."""
    record = blank_record(task)
    record.update({k: (facts or {}).get(k) for k in FACTS})
    record.update(status="time limit", seconds=seconds,
                  message=f"stopped after {seconds:.3g} s (time limit {limit:g} s)")
    return record
