"""The first small calls of a cold process run the kernels' Python text instead of compiling
(impactqp/kernels/first_calls.py): the answers are the compiled ones, nothing is compiled that
the call did not need, and compilation comes back as soon as it pays — machine code in the
cache, a large call, the interpreted budget spent, or ``impactqp compile``."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
from compile_count import COUNTER

# Runs in a fresh process with an empty cache; prints what happened as "key value" lines.
PROBE = COUNTER + """
import numpy as np
import impactqp as iq
from impactqp.kernels import first_calls, units
{body}
print("compilations", Count.n)
print("interpreted", first_calls.spent()[1])
print("signatures", len(units.contact_units.signatures))
"""


def _run(body: str, cache, budget: str | None = None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_DISABLE_JIT", "IMPACTQP_INTERPRETED_SECONDS")}
    env["NUMBA_CACHE_DIR"] = str(cache)
    if budget is not None:
        env["IMPACTQP_INTERPRETED_SECONDS"] = budget
    done = subprocess.run([sys.executable, "-c", PROBE.replace("{body}", body)], env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return dict(line.split(" ", 1) for line in done.stdout.splitlines() if " " in line)


SMALL_UNITS = "units.contact_units(np.array([4.0, 1.0, 2.0]), 3)"
LARGE_UNITS = "units.contact_units(np.ones(3 * 2000), 3)"


def test_cold_small_calls_compile_nothing_and_answer_as_compiled(tmp_path):
    body = """
p = iq.newtons_cradle(3, 1.0)
r = iq.moreau(p, 0.5)
f = iq.solve(iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0]), iq.Coulomb(0.3, 0.5))
assert r.certificate.ok and f.certificate.ok
print("moreau", " ".join(repr(float(x)) for x in r.u_plus))
print("coulomb", " ".join(repr(float(x)) for x in f.u_plus))
"""
    cold = _run(body, tmp_path / "cold")
    assert cold["compilations"] == "0"  # no kernel compiled: a cold demo-sized session
    assert int(cold["interpreted"]) >= 2
    # the machine code of the session's cache (filled by tests/test_compile_ahead.py)
    from impactqp.kernels import jit

    session = os.environ.get("NUMBA_CACHE_DIR") or jit.cache_dir()
    compiled = _run(body, session, budget="0")
    assert compiled["interpreted"] == "0"
    for key in ("moreau", "coulomb"):
        a = np.array(cold[key].split(), dtype=float)
        b = np.array(compiled[key].split(), dtype=float)
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-14)


def test_the_cache_a_large_call_or_a_spent_budget_compile(tmp_path):
    cache = tmp_path / "numba"
    first = _run(SMALL_UNITS, cache)
    assert (first["compilations"], first["interpreted"], first["signatures"]) == ("0", "1", "0")
    large = _run(LARGE_UNITS, cache)  # above first_calls.SMALL elements: compiled
    assert large["interpreted"] == "0" and large["signatures"] == "1"
    warm = _run(SMALL_UNITS, cache)  # its machine code is in the cache now: loaded
    assert (warm["compilations"], warm["interpreted"], warm["signatures"]) == ("0", "0", "1")
    spent = _run(f"{SMALL_UNITS}\n{SMALL_UNITS}", tmp_path / "other", budget="1e-12")
    assert spent["interpreted"] == "1" and spent["signatures"] == "1"  # the second compiles


def test_compiling_block_and_impactqp_compile_never_interpret(tmp_path):
    body = f"""
with first_calls.compiling():
    {SMALL_UNITS}
"""
    done = _run(body, tmp_path / "numba")
    assert done["interpreted"] == "0" and done["signatures"] == "1"


def test_python_text_is_the_same_definition_as_the_kernel():
    from impactqp.kernels import first_calls, impact, jit, units

    twin = first_calls.python_text(units.contact_units)
    assert twin.__code__.co_code == units.contact_units.py_func.__code__.co_code
    assert twin.__module__ == first_calls.TWIN + ".units"
    assert not hasattr(twin, "signatures")  # plain Python, not a dispatcher
    # its callees are plain Python too: the whole call tree runs interpreted
    solve = first_calls.python_text(impact.solve_impact)
    callees = [v for k, v in solve.__globals__.items() if callable(v) and hasattr(v, "__code__")
               and getattr(v, "__module__", "").startswith(first_calls.TWIN)]
    assert callees and not any(hasattr(v, "signatures") for v in callees)
    # the twin imports its decorators from a module of its own, never registering a second
    # compile notice; the real kernels keep theirs
    assert sys.modules[first_calls.TWIN + ".jit"] is not jit
    assert hasattr(units.contact_units, "signatures") or os.environ.get("NUMBA_DISABLE_JIT")


@pytest.mark.parametrize("seed", range(3))
def test_python_text_answers_as_the_machine_code(seed):
    """The interpreted single impact equals the compiled one on random problems."""
    import impactqp as iq
    from impactqp.kernels import first_calls
    from impactqp.laws import small

    p = iq.random_impact(9, 5, seed=seed)
    compiled = iq.moreau(p, 0.3)
    kernel = small.solve_impact
    if not hasattr(kernel, "py_func"):
        pytest.skip("NUMBA_DISABLE_JIT: every kernel is Python already")
    twin, calls = first_calls.python_text(kernel), []

    def counted(*args):
        calls.append(args)
        return twin(*args)

    try:
        small.solve_impact = counted
        interpreted = iq.moreau(p, 0.3)
    finally:
        small.solve_impact = kernel
    assert calls and interpreted.certificate.ok
    np.testing.assert_allclose(interpreted.u_plus, compiled.u_plus, rtol=1e-12, atol=1e-13)
    np.testing.assert_allclose(interpreted.impulses, compiled.impulses, rtol=1e-11,
                               atol=1e-13)


def test_every_kernel_module_imports_as_python_text():
    """Each kernel's twin exists, with its relative imports (``..errors``, ``.jit``) resolved
    as in the compiled package."""
    import importlib
    import pkgutil

    from impactqp import kernels
    from impactqp.kernels import first_calls

    interpretable = 0
    for info in pkgutil.iter_modules(kernels.__path__):
        module = importlib.import_module(f"{kernels.__name__}.{info.name}")
        for value in vars(module).values():
            if getattr(value, "py_func", None) is not None and \
                    value.py_func.__module__ == module.__name__:
                twin = first_calls.python_text(value)
                assert twin.__code__.co_code == value.py_func.__code__.co_code
                interpretable += isinstance(value, first_calls.InterpretableDispatcher)
    if not os.environ.get("NUMBA_DISABLE_JIT"):
        assert interpretable >= 10
