"""Sweeps that scale out: run independent chunks of work on local processes or on a Dask
cluster, with a progress bar, and gather the results in chunk order.

The work of a sweep is fixed before it is split (the samples are drawn from the seed first),
so the results do not depend on the number of workers or on the order in which chunks end.
"""

from __future__ import annotations

import math
import multiprocessing
import sys
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any, TypeVar

from tqdm import tqdm

from ..base.arrays import as_count
from ..errors import InputError

T = TypeVar("T")
R = TypeVar("R")

DASK_MIN_IMPACTS = 10_000
"""Least impacts per Dask task: below that, scheduling costs more than the work."""

_WORK: Callable[[Any], Any] | None = None  # the function forked workers inherit


def _run_inherited(item: Any) -> Any:
    assert _WORK is not None
    return _WORK(item)


def check_jobs(n_jobs: Any, client: Any) -> int:
    """``n_jobs`` as a positive whole number (-1: every core); ``client`` must look like a
    dask.distributed Client when given."""
    if n_jobs == -1:
        n_jobs = multiprocessing.cpu_count()
    n_jobs = as_count("n_jobs", n_jobs, minimum=1)
    if client is not None and not (hasattr(client, "map") and hasattr(client, "gather")):
        raise InputError(f"client must be a dask.distributed Client, got {type(client).__name__}")
    return n_jobs


def split(n_items: int, n_jobs: int, *, client: Any = None, impacts_per_item: int = 1,
          min_chunk: int = 1) -> list[range]:
    """Consecutive ranges covering ``n_items``: about four per worker locally; on Dask, each
    holding at least :data:`DASK_MIN_IMPACTS` impacts."""
    if n_items == 0:
        return []
    if client is not None:
        size = max(math.ceil(DASK_MIN_IMPACTS / max(impacts_per_item, 1)), min_chunk)
    elif n_jobs == 1:
        size = max(math.ceil(n_items / 20), min_chunk)  # a few steps for the progress bar
    else:
        size = max(math.ceil(n_items / (4 * n_jobs)), min_chunk)
    return [range(a, min(a + size, n_items)) for a in range(0, n_items, size)]


def run_chunks(work: Callable[[T], R], chunks: Sequence[T], *, n_jobs: int = 1,
               client: Any = None, desc: str = "", progress: bool | None = None) -> list[R]:
    """``[work(c) for c in chunks]``, in that order, on ``n_jobs`` local processes or on a
    Dask cluster (``client``), with a progress bar on stderr.

    Parameters
    ----------
    work : callable
        Applied to each chunk. Local processes inherit it by forking (any callable works on
        Linux); Dask ships it with cloudpickle.
    chunks : sequence
    n_jobs : int
        Local worker processes (1: in this process).
    client : dask.distributed.Client, optional
        Run on this cluster instead of local processes.
    desc : str
        Label of the progress bar.
    progress : bool or None
        Show the bar; None shows it only when stderr is a terminal.

    Returns
    -------
    list
        The results in the order of ``chunks``.
    """
    disable = (not sys.stderr.isatty()) if progress is None else not progress
    bar = tqdm(total=len(chunks), desc=desc, disable=disable, file=sys.stderr, leave=False)
    try:
        if client is not None:
            futures = client.map(work, list(chunks), pure=False)
            if not disable:
                _follow_dask(futures, bar)
            return client.gather(futures)
        if n_jobs == 1 or len(chunks) < 2:
            out = []
            for chunk in chunks:
                out.append(work(chunk))
                bar.update()
            return out
        return _run_local(work, chunks, n_jobs, bar)
    finally:
        bar.close()


def _follow_dask(futures: list, bar: tqdm) -> None:
    from distributed import as_completed as dask_completed  # the optional "dask" extra

    for _ in dask_completed(futures):
        bar.update()


def _run_local(work: Callable[[T], R], chunks: Sequence[T], n_jobs: int, bar: tqdm) -> list[R]:
    global _WORK
    methods = multiprocessing.get_all_start_methods()
    if "fork" in methods:
        _WORK = work
        context = multiprocessing.get_context("fork")
        call, items = _run_inherited, list(chunks)
    else:  # spawn: the callable itself must be picklable
        context = multiprocessing.get_context()
        call, items = work, list(chunks)
    try:
        results: list[Any] = [None] * len(items)
        with ProcessPoolExecutor(max_workers=n_jobs, mp_context=context) as pool:
            pending = {pool.submit(call, item): i for i, item in enumerate(items)}
            for future in as_completed(pending):
                results[pending[future]] = future.result()
                bar.update()
        return results
    finally:
        _WORK = None
