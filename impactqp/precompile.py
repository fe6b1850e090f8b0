"""Compile impactqp's kernels ahead of time, for images, containers and cluster workers.

Every kernel is compiled by numba on its first call and its machine code kept in the cache
folder (:func:`impactqp.kernels.jit.cache_dir`). :func:`compile_kernels` makes those first
calls on small problems of every route — impacts of each law, batches, chains, S, friction,
and both Moreau–Jean loops — so that later processes sharing the cache start warm.
"""

from __future__ import annotations

import importlib
import multiprocessing
import pkgutil
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass

import numba
import numpy as np

from . import kernels
from .derivatives.batch import derivative_batch
from .derivatives.solve import derivative
from .errors import InputError
from .kernels.first_calls import cached, compiling
from .kernels.jit import NOTICE, cache_dir
from .laws.batch import solve_batch
from .laws.complementarity import Fremond, Newton
from .laws.coulomb import Coulomb
from .laws.friction import solve_friction
from .laws.functions import moreau, sector_law
from .laws.lzb import LZB
from .laws.moreau import Moreau
from .laws.pipeline import solve
from .model.builders import chain, newtons_cradle, random_impact
from .model.classify import classify
from .model.friction import FrictionContactProblem
from .model.friction_builders import sphere_on_plane
from .simulation.builders import block_on_incline, bouncing_ball, box_on_floor, cradle_system
from .simulation.simulate import simulate


def _impacts() -> None:
    p = newtons_cradle(3, 1.0)
    for eps in (0.0, 1.0):
        moreau(p, eps)
    solve(p, Newton([1.0, 0.5]))
    solve(p, Fremond([[0.5, 0.2], [0.0, 0.5]]))
    sector_law(p)
    p.admissible_set().contains([0.0, 0.0, 1.0])
    r = random_impact(8, 5, seed=1)
    moreau(r, 0.5)
    for law in (Moreau(0.5), Fremond(0.2 * np.eye(5))):  # the compiled derivative
        d = derivative(r, law)
        d.jvp(u_minus=r.u_minus)
        d.vjp(u_plus=r.u_minus)


def _nnls_and_classes() -> None:
    moreau(random_impact(8, 5, seed=1), 0.5, backend="nnls")
    classify(newtons_cradle(3, 1.0), [0.0, 0.0, 1.0])


def _batches() -> None:
    p = newtons_cradle(3, 1.0)
    U = np.random.default_rng(0).standard_normal((64, 3))
    solve_batch(p, Moreau(0.5), U)
    solve_batch(p, Newton([1.0, 0.5]), U)
    derivative_batch(p, Moreau(0.5), U, jvp=U, vjp=U)


def _chains() -> None:
    masses = np.linspace(1.0, 2.0, 2000)
    u = np.zeros(2000)
    u[0] = 1.0
    moreau(chain(masses, u), 1.0)


def _lzb() -> None:
    solve(newtons_cradle(3, 1.0), LZB(1.0, 1.5, 0.9))


def _friction() -> None:
    p = sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])
    solve(p, Coulomb(0.3, 0.5)).derivative().jvp(u_minus=p.u_minus)
    rng = np.random.default_rng(2)
    m = 40
    A = rng.standard_normal((3 * m, 3 * m + 5))
    W = A @ A.T / (3 * m)
    q = rng.standard_normal(3 * m)
    problem = FrictionContactProblem(W, q, 0.3)
    for backend in ("auto", "nsgs", "newton"):
        solve_friction(problem, backend=backend)
    solve_friction(FrictionContactProblem(W[:9, :9], q[:9], 0.3))  # a few contacts: one call


def _simulations() -> None:
    simulate(bouncing_ball(q0=0.1), Newton(0.5), 0.2, h=1e-2)
    simulate(cradle_system(3), Moreau(1.0), 0.05, h=1e-3)
    simulate(bouncing_ball(q0=0.1), Newton(0.5), 0.2, h=1e-2,
             sensitivities=("q0", "e")).vjp(q=[1.0])  # the discrete map and its adjoint


def _frictional_simulations() -> None:
    simulate(block_on_incline(0.3, dim=2, speed=1.0), Coulomb(0.5, 0.0), 0.05, h=1e-2)
    simulate(box_on_floor(3, velocity=[1.0, 0.0]), Coulomb(0.3, 0.0), 0.05, h=1e-2)


STAGES: tuple[tuple[str, Callable[[], None]], ...] = (
    ("impacts", _impacts), ("NNLS and classes", _nnls_and_classes), ("batches", _batches),
    ("chains", _chains), ("LZB", _lzb),
    ("friction", _friction), ("simulations", _simulations),
    ("frictional simulations", _frictional_simulations),
)
"""The routes :func:`compile_kernels` runs, by name."""

LONGEST_FIRST = ("friction", "impacts", "simulations", "batches", "LZB",
                 "frictional simulations", "NNLS and classes", "chains")
"""The stages by their compile time (measured), the order a parallel compile of three
processes or more starts them in, one stage per task."""

PAIRED = (("friction", "frictional simulations", "NNLS and classes"),
          ("impacts", "batches", "chains", "simulations", "LZB"))
"""The stages of a compile in two processes, one group each, run in this order: the stages
of a group share most of their kernels (the frictional steps of a simulation call
friction's sweeps; batches, chains and the frictionless Moreau–Jean loops the active-set
search and residuals of an impact), so each is compiled once in its process instead of in
both. LZB shares nothing and goes where it evens the groups' CPU times. The NNLS backend
and the classes of an answer come last in the frictional group: by then the other group has
written the active-set search and residuals they share with an impact to the cache, so only
their own kernels are compiled (measured, both groups at once sharing an empty cache: CPU
52.3 s and 59.2 s before this move, 56.3 s and 55.3 s after; since the friction kernels
compile their shared code once, 52.5 s and 61.7 s, and moving "chains" to the frictional
group made it 63.5 s and 67.2 s in the same period)."""


@dataclass(frozen=True)
class CompileReport:
    """What :func:`compile_kernels` did.

    Attributes
    ----------
    seconds : float
        Wall-clock time of all stages.
    compiled : tuple of str
        Kernels that hold machine code afterwards (``module.function``).
    not_reached : tuple of str
        Kernels without machine code of their own: helpers compiled into the kernels that
        call them (a test checks that after this call the routes compile nothing more).
    cache : str
        The cache folder the machine code was written to.
    """

    seconds: float
    compiled: tuple[str, ...]
    not_reached: tuple[str, ...]
    cache: str

    def summary(self) -> str:
        """One line for the command line."""
        return (f"{len(self.compiled)} kernels ready in {self.seconds:.1f} s "
                f"(cache: {self.cache})")


def _kernels() -> dict[str, object]:
    """Every compiled kernel of :mod:`impactqp.kernels` by ``module.function``."""
    found: dict[str, object] = {}
    for info in pkgutil.iter_modules(kernels.__path__):
        module = importlib.import_module(f"{kernels.__name__}.{info.name}")
        for name, value in vars(module).items():
            if getattr(value, "py_func", None) is not None and \
                    value.py_func.__module__ == module.__name__:
                found[f"{info.name}.{name}"] = value
    return found


def _run_stages(names: tuple[str, ...], quiet: bool = False) -> None:
    """Run the named stages, compiling every kernel they call (never their Python text)."""
    if quiet:  # a worker of a parallel compile: the parent has said it once
        NOTICE.said = True
    stages = dict(STAGES)
    with compiling():  # small first calls would otherwise run as Python (kernels/first_calls)
        for name in names:
            stages[name]()


def compile_kernels(progress: Callable[[str, int, int], None] | None = None,
                    jobs: int = 1) -> CompileReport:
    """Compile every kernel impactqp's routes call, writing their machine code to the cache.

    Parameters
    ----------
    progress : callable, optional
        Called as ``progress(stage, done, total)`` before each stage (as each finishes, with
        ``jobs`` > 1, with the stages that finished) and once at the end.
    jobs : int
        Processes compiling at once (``impactqp compile`` uses one per core), each writing
        to the same cache: two run two groups of stages (``PAIRED``), more the stages one by
        one, longest first. This process runs the first group (or stage) itself while
        ``jobs`` − 1 processes it starts run the others: a process started imports
        impactqp again, about a second before it compiles anything. 1 compiles in this
        process alone (a dask worker, which may not start processes of its own).

    Returns
    -------
    CompileReport
    """
    if not isinstance(jobs, int) or jobs < 1:
        raise InputError(f"jobs must be a positive integer (processes compiling at once), "
                         f"got {jobs!r}")
    start = time.perf_counter()
    names = [name for name, _ in STAGES]
    if jobs == 1:
        for i, name in enumerate(names):
            if progress is not None:
                progress(name, i, len(names))
            _run_stages((name,))
    else:
        NOTICE.say()
        context = multiprocessing.get_context("spawn")
        tasks = PAIRED if jobs == 2 else tuple((name,) for name in LONGEST_FIRST)
        own, others = tasks[0], tasks[1:]  # the longest in this process, imported already
        with ProcessPoolExecutor(max_workers=min(jobs, len(tasks)) - 1,
                                 mp_context=context) as pool:
            futures = {pool.submit(_run_stages, task, True): task for task in others}
            _run_stages(own, True)
            done = len(own)
            if progress is not None:
                progress(", ".join(own), done, len(names))
            for future in as_completed(futures):
                future.result()
                done += len(futures[future])
                if progress is not None:
                    progress(", ".join(futures[future]), done, len(names))
    if progress is not None:
        progress("done", len(names), len(names))
    found = _kernels()
    compiled = tuple(sorted(k for k, v in found.items() if v.signatures or cached(v)))
    missing = tuple(sorted(k for k in found if k not in compiled))
    return CompileReport(time.perf_counter() - start, compiled, missing,
                         numba.config.CACHE_DIR or cache_dir())
