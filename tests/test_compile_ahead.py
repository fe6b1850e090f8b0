"""Compilation is seen and done ahead of time: ``impactqp compile`` fills the cache so that a
later process compiles nothing on the README's routes, and a cold first call says once on
stderr that it compiles, while a warm one stays silent."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from compile_count import COUNTER

NOTICE = "impactqp: compiling its numba kernels"

# A later process's routes, with a listener counting every compilation of impactqp's kernels.
ROUTES = COUNTER + """
import numpy as np
import impactqp as iq

p = iq.newtons_cradle(3, 1.0)
iq.moreau(p, 1.0); iq.moreau(p, 0.0); iq.sector_law(p)
iq.solve_batch(p, iq.Moreau(0.5), np.random.default_rng(0).standard_normal((10, 3)))
iq.solve(iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0]), iq.Coulomb(0.3, 0.5))
iq.simulate(iq.simulation.bouncing_ball(q0=0.1), iq.Newton(0.5), 0.2, h=1e-2)
iq.simulate(iq.simulation.block_on_incline(0.3, dim=2, speed=1.0), iq.Coulomb(0.5, 0.0), 0.05,
            h=1e-2)
print("compilations", Count.n)
"""


def _env(cache) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_JIT"}
    env["NUMBA_CACHE_DIR"] = str(cache)
    return env


@pytest.mark.timeout(900)
def test_compile_fills_the_cache_and_later_processes_compile_nothing(tmp_path):
    cache = tmp_path / "numba"
    # its own session, and first in the suite (tests/conftest.py): run after the dask tests,
    # the compile was ended by SIGTERM in one CI run (returncode -15)
    done = subprocess.run([sys.executable, "-m", "impactqp", "compile", "--list"],
                          env=_env(cache), capture_output=True, text=True, timeout=850,
                          start_new_session=True)
    assert done.returncode == 0, done.stderr
    assert "kernels ready" in done.stdout
    assert done.stderr.count(NOTICE) == 1, done.stderr  # said once, however many kernels
    assert str(cache) in done.stderr
    later = subprocess.run([sys.executable, "-c", ROUTES], env=_env(cache),
                           capture_output=True, text=True, timeout=300,
                           start_new_session=True)
    assert later.returncode == 0, later.stderr
    assert "compilations 0" in later.stdout, later.stdout
    assert NOTICE not in later.stderr
    # the machine code is this checkout's: the rest of the session loads it from its own cache
    # instead of compiling every kernel a second time (files already there are kept)
    from impactqp.kernels import jit

    session = Path(os.environ.get("NUMBA_CACHE_DIR") or jit.cache_dir())
    for source in cache.rglob("*"):
        target = session / source.relative_to(cache)
        if source.is_file() and not target.exists():
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target)


def test_notice_is_written_once_and_only_after_its_delay():
    import io

    from impactqp.kernels import jit

    out = io.StringIO()
    notice = jit.CompileNotice(lambda: out)

    class Event:  # the part of numba's event the listener reads
        def __init__(self, module):
            self.data = {"dispatcher": type("D", (), {"py_func": type(
                "F", (), {"__module__": module})})()}

    ours, theirs = Event("impactqp.kernels.impact"), Event("somebody.else")
    notice.on_start(theirs)
    assert notice.timer is None  # other packages' kernels are not ours to announce
    notice.on_start(ours)
    notice.on_start(ours)  # nested: one timer
    notice.on_end(ours)
    assert notice.timer is not None
    notice.on_end(ours)  # finished within the delay: nothing said
    assert notice.timer is None and out.getvalue() == ""
    notice.say()
    notice.say()
    assert out.getvalue().count(NOTICE) == 1


@pytest.mark.parametrize("jobs", [0, -1, 1.5, "2"])
def test_compile_refuses_a_bad_number_of_processes(jobs):
    from impactqp.errors import InputError
    from impactqp.precompile import compile_kernels

    with pytest.raises(InputError, match="jobs must be a positive integer"):
        compile_kernels(jobs=jobs)


def test_compile_command_names_a_bad_jobs_flag():
    done = subprocess.run([sys.executable, "-m", "impactqp", "compile", "--jobs", "0"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert "--jobs" in done.stderr and "positive integer" in done.stderr


def test_a_parallel_compile_starts_every_stage():
    from impactqp import precompile

    names = sorted(name for name, _ in precompile.STAGES)
    assert sorted(precompile.LONGEST_FIRST) == names
    assert sorted(name for group in precompile.PAIRED for name in group) == names


def test_an_internal_kernel_runs_inside_its_callers_and_refuses_a_call_from_python():
    """A kernel compiled without the wrapper for calls from Python (kernel(internal=True))
    gives its callers the same answer as its Python text, and a direct call raises instead
    of jumping into code that was never built."""
    import numba
    import numpy as np

    from impactqp.kernels import jit, residuals

    um, up, lam = np.array([0.0, 0.0]), np.array([3e61, -1.0]), np.array([-4e61])
    assert residuals.unit_of(um, up, lam) == 4e61  # _largest of u⁺ and Λ, compiled inside
    if not numba.config.DISABLE_JIT:
        with pytest.raises(TypeError, match="called only by other kernels"):
            residuals._largest(up)
    with pytest.raises(TypeError, match="exclude each other"):
        jit.kernel(lambda x: x, interpretable=True, internal=True)


def test_read_only_inside_a_kernel_gives_its_callee_one_signature():
    """``read_only`` called by a kernel types its array read-only without a copy, so a callee
    given writable and read-only arrays by its callers compiles once (the Moreau–Jean loop's
    certificates and an impact's share theirs this way); from Python it is a read-only view."""
    import numba
    import numpy as np

    from impactqp.kernels.jit import read_only

    @numba.njit
    def first(a):
        return a[0]

    @numba.njit
    def both(a):
        b = a.copy()  # writable
        b[0] = 5.0
        return first(read_only(b)) + first(read_only(a))

    x = np.arange(1.0, 4.0)
    view = read_only(x)
    assert not view.flags.writeable and np.shares_memory(view, x)
    assert both(x) == 6.0 and both(view) == 6.0
    if not numba.config.DISABLE_JIT:
        assert [sig[0].mutable for sig in first.signatures] == [False]


# A long chain solved alone (solve_chain) and a chain batch with a wall and rows outside the
# unit range (each certified row by row again): the callers of the shared certificate kernels
# in two modules.
SHARED = """
import numpy as np
import impactqp as iq
from impactqp.kernels import chain_batch, residuals

masses, u = np.linspace(1.0, 2.0, 2000), np.zeros(2000)
u[0] = 1.0
iq.moreau(iq.chain(masses, u), 1.0)
Um = np.random.default_rng(0).standard_normal((300, 3))
Um[3] *= 1e70
ones = np.ones(3)
chain_batch.chain_residual_columns(Um, Um.copy(), np.ones((300, 3)), ones, ones, ones, False,
                                   True, 0.5, 0.5, True, np.empty((6, 300)))
print("signatures", len(residuals.chain_residuals.signatures),
      len(chain_batch._gather.signatures))
"""


def test_shared_kernels_compile_once_for_both_callers(tmp_path):
    """chain_residuals (called by the single chain's solve and, for rows outside the unit
    range, by the batch certificate) and the batch's gather (a ball, then the wall) each hold
    one signature: another would compile them, and every kernel they call, once more. An
    empty cache: a caller loaded from the cache compiles none of its callees."""
    done = subprocess.run([sys.executable, "-c", SHARED], capture_output=True, text=True,
                          timeout=300, env=_env(tmp_path / "numba"))
    assert done.returncode == 0, done.stderr
    assert "signatures 1 1" in done.stdout, done.stdout
