"""The Python path around the compiled call of a few contacts (impactqp/laws/friction.py's
solve_friction, impactqp/laws/friction_small.py's solve_few and SmallFrictionResult): every
solve fills an array of its own, so a result never changes with a later solve; a problem
whose q is rewritten in place, or whose W or μ is replaced, after it was packed is solved as
it now is; a bad tolerance, backend or problem is refused on the packed path as on the first
solve; and the thin result reads, pickles and compares as a FrictionResult, with the
tolerance of its own call."""

from __future__ import annotations

import dataclasses
import math
import pickle

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from benchmarks import friction_data
from impactqp.errors import InputError, NonFiniteError, UnknownBackendError
from impactqp.kernels.friction_tiny import CERTIFIED
from impactqp.kernels.jit import machine_code
from impactqp.laws import friction_small
from impactqp.laws.friction_small import SmallFrictionResult
from impactqp.model.friction import certify_friction

TOL = 1e-8
NAMES = ("CubeH8", "FC3D-1c", "Rover11211", "FC2D-00394", "FC2D-00031", "Confeti-ex13-4c")
"""1-contact 3-D (sparse and dense W), 2-D problems the first sweep ends (dense and sparse)
and a 4-contact one solved by the method whole."""


def packed(problem: iq.FrictionContactProblem) -> bool:
    """Whether the route has packed ``problem`` (solved it twice for its present state)."""
    kept = problem.__dict__.get(friction_small._KEPT)
    return kept is not None and kept.packed is not None


def fresh_answer(problem: iq.FrictionContactProblem, backend: str = "auto"):
    """The answer of a new problem holding copies of ``problem``'s present arrays."""
    W = problem.W.copy()
    again = iq.FrictionContactProblem(W, problem.q.copy(), problem.mu.copy(),
                                      contact_dim=problem.contact_dim)
    return iq.solve_friction(again, tol=TOL, backend=backend)


@pytest.mark.parametrize("name", NAMES)
def test_a_result_never_changes_with_later_solves(name: str) -> None:
    """Results of the first solve, of the packing solve and of solves from the pack, each
    read only after every later solve (and after q was rewritten in place and solved):
    each holds its own array and its first answer, certified apart."""
    problem = friction_data.load(name).problem
    q0 = problem.q.copy()
    results = [iq.solve_friction(problem, tol=TOL) for _ in range(4)]
    assert packed(problem)
    problem.q[:] = -2.0 * q0  # in place: the next solve answers another problem
    other = iq.solve_friction(problem, tol=TOL)
    iq.solve_friction(problem, tol=TOL)
    problem.q[:] = q0
    calls = [res._call[0] for res in results]  # the arrays the calls filled
    for i, res in enumerate(results):
        assert type(res) is SmallFrictionResult
        assert not any(np.shares_memory(calls[i], c) for c in calls[i + 1:])
        assert not np.shares_memory(calls[i], other._call[0])
        np.testing.assert_array_equal(res.r, results[0].r)
        np.testing.assert_array_equal(res.u, results[0].u)
        assert res.certificate.values == results[0].certificate.values
        assert certify_friction(problem, res.r, res.u, tol=TOL).ok
    assert not np.array_equal(other.u, results[0].u)


@pytest.mark.parametrize("backend", ["auto", "kernel"])
@pytest.mark.parametrize("name", ["CubeH8", "FC2D-00394", "Confeti-ex13-4c"])
def test_q_rewritten_in_place_after_packing_is_solved_as_it_now_is(name: str,
                                                                   backend: str) -> None:
    """Packed, then q rewritten in place step after step (a simulator's loop): each solve
    is the answer of a new problem of the present q, and the pack is made again for it."""
    problem = friction_data.load(name).problem
    rng = np.random.default_rng(7)
    for _step in range(3):
        for _ in range(3):
            res = iq.solve_friction(problem, tol=TOL, backend=backend)
        assert packed(problem)
        assert certify_friction(problem, res.r, res.u, tol=TOL).ok
        np.testing.assert_allclose(res.u, fresh_answer(problem, backend).u,
                                   atol=1e-9 * np.abs(res.u).max())
        problem.q[:] = problem.q * rng.uniform(0.5, 1.5, problem.q.size)


@pytest.mark.parametrize("form", ["as it is", "csr", "coo", "dense"])
@pytest.mark.parametrize("name", ["CubeH8", "FC3D-1c", "FC2D-00031"])
def test_w_replaced_after_packing_is_solved_as_it_now_is(name: str, form: str) -> None:
    """A new W object (here W scaled by 3, so every answer r is a third of the old one; in
    a sparse format the problem does not make itself, or dense) is solved for, not answered
    from the pack of the old W."""
    problem = friction_data.load(name).problem
    for _ in range(3):
        old = iq.solve_friction(problem, tol=TOL)
    W = problem.W * 3.0
    if form == "dense":
        W = W.toarray() if sp.issparse(W) else W
    elif form != "as it is":
        W = getattr(sp, f"{form}_matrix")(W)
    problem.W = W
    new = iq.solve_friction(problem, tol=TOL)
    assert certify_friction(problem, new.r, new.u, tol=TOL).ok
    np.testing.assert_allclose(new.r, old.r / 3.0, rtol=1e-9, atol=1e-12 * np.abs(old.r).max())
    for _ in range(2):  # packed again, for the new W
        again = iq.solve_friction(problem, tol=TOL)
    assert packed(problem)
    np.testing.assert_array_equal(again.r, new.r)


def test_mu_replaced_after_packing_is_solved_as_it_now_is() -> None:
    problem = friction_data.load("CubeH8").problem
    for _ in range(3):
        iq.solve_friction(problem, tol=TOL)
    problem.mu = np.zeros(1)  # frictionless: the tangential reaction vanishes
    res = iq.solve_friction(problem, tol=TOL)
    assert np.all(res.r[1:] == 0.0)
    np.testing.assert_allclose(res.u, fresh_answer(problem).u, atol=1e-12)


@pytest.mark.parametrize("tol, error", [(0.0, InputError), (1.0, InputError),
                                        (-1e-8, InputError), (2, InputError),
                                        (math.nan, NonFiniteError), (math.inf, NonFiniteError),
                                        ("1e-8", InputError), (True, InputError),
                                        (None, InputError), (np.array([1e-8]), InputError)])
def test_a_bad_tolerance_is_refused_on_the_packed_path(tol, error) -> None:
    problem = friction_data.load("CubeH8").problem
    for _ in range(3):
        iq.solve_friction(problem, tol=TOL)
    assert packed(problem)
    with pytest.raises(error):
        iq.solve_friction(problem, tol=tol)
    with pytest.raises(error):  # the same on a fresh problem's first solve
        fresh_answer_tol(problem, tol)


def fresh_answer_tol(problem: iq.FrictionContactProblem, tol) -> None:
    again = iq.FrictionContactProblem(problem.W.copy(), problem.q.copy(), problem.mu.copy(),
                                      contact_dim=problem.contact_dim)
    iq.solve_friction(again, tol=tol)


@pytest.mark.parametrize("tol", [np.float64(1e-8), np.array(1e-8), 1e-6, 0.5])
def test_a_tolerance_of_another_type_or_value_is_the_calls_own(tol) -> None:
    """numpy numbers are taken as floats, and each result's certificate is judged at the
    tolerance of its own call, though the calls share the pack."""
    problem = friction_data.load("Rover11211").problem
    for _ in range(3):
        first = iq.solve_friction(problem, tol=TOL)
    res = iq.solve_friction(problem, tol=tol)
    assert type(res) is SmallFrictionResult
    assert res.certificate.tol == float(tol) and type(res.certificate.tol) is float
    assert first.certificate.tol == TOL
    np.testing.assert_array_equal(res.r, first.r)


def test_bad_backend_and_problem_are_refused_on_the_packed_path() -> None:
    problem = friction_data.load("CubeH8").problem
    for _ in range(3):
        iq.solve_friction(problem, tol=TOL)
    with pytest.raises(UnknownBackendError):
        iq.solve_friction(problem, backend="no-such-method")
    with pytest.raises(InputError):
        iq.solve_friction((problem.W, problem.q, problem.mu))


@pytest.mark.parametrize("backend", ["auto", "kernel", "nsgs", "newton"])
def test_every_route_gives_the_same_answer_again(backend: str) -> None:
    """The first, second and later solves of one problem on each route: the same answer,
    each certified apart; only the few-contact routes give thin results."""
    problem = friction_data.load("Confeti-ex13-4c").problem
    results = [iq.solve_friction(problem, tol=TOL, backend=backend) for _ in range(4)]
    for res in results:
        assert res.backend == results[0].backend and res.ok
        assert (type(res) is SmallFrictionResult) == (backend in ("auto", "kernel"))
        np.testing.assert_array_equal(res.r, results[0].r)
        assert res.attempts == results[0].attempts
        assert certify_friction(problem, res.r, res.u, tol=TOL).ok


@pytest.mark.parametrize("form", ["dense", "csr", "csc", "coo"])
def test_the_thin_result_reads_pickles_and_compares(form: str) -> None:
    """Every FrictionResult attribute of a result from the pack, after pickling, and after
    dataclasses.replace (which makes a result of fields, no compiled call)."""
    W = np.array([[2.0, 0.3, 0.2], [0.1, 1.5, 0.0], [0.2, 0.05, 1.2]])  # not symmetric
    problem = iq.FrictionContactProblem(W, np.array([-1.0, 2.0, -1.0]), 0.3)
    if form != "dense":  # as a caller may set it (the problem makes CSC of a sparse W)
        problem.W = getattr(sp, f"{form}_matrix")(W)
    for _ in range(3):
        res = iq.solve_friction(problem, tol=TOL)
    assert packed(problem) and type(res) is SmallFrictionResult
    assert set(res.__dict__) == {"_call"}  # nothing built before it is asked for
    assert res.ok and res.success and res.status == "solved"
    assert res.backend == "kernel" and res.iterations == 1 and res.solve_time > 0
    assert res.attempts == ["solved in its contacts' units (2^0)", "kernel (friction): certified"]
    assert res.error == res.certificate.error <= 1e-14 and res.certificate.ok
    assert res.r.size == res.u.size == 3
    np.testing.assert_allclose(res.u, problem.velocity(res.r), atol=1e-14)
    assert "solved by kernel in 1 iterations" in res.message
    copy = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(copy.r, res.r)
    assert (copy.backend, copy.iterations, copy.attempts) == (res.backend, 1, res.attempts)
    assert copy.certificate.values == res.certificate.values and copy.ok
    replaced = dataclasses.replace(res, iterations=7)
    assert replaced.iterations == 7 and replaced.ok and replaced.backend == "kernel"
    assert "_call" not in replaced.__dict__
    assert res == dataclasses.replace(res)


def test_solves_from_a_pack_call_the_machine_code_a_first_solve_found() -> None:
    """Once a pack's first solve found solve_packed's machine code, solves from a pack call
    it without numba's dispatch: the same answers as through the dispatcher. The solves
    compile what they call: with an empty cache a process's first small calls run as Python
    (kernels/first_calls.py), and there is no machine code to find."""
    from impactqp.kernels.first_calls import compiling
    from impactqp.kernels.friction_packed import iterations_at, solve_packed

    problem = friction_data.load("FC2D-00394").problem
    with compiling():
        results = [iq.solve_friction(problem, tol=TOL) for _ in range(3)]
    pack = problem.__dict__[friction_small._KEPT].packed
    code = friction_small._solve_from_pack
    if hasattr(solve_packed, "overloads"):  # numba on (not NUMBA_DISABLE_JIT)
        assert code is not solve_packed and callable(code)
    out, again = np.empty(pack.out_size), np.empty(pack.out_size)
    assert code(pack.floats, pack.ints, TOL, out) == CERTIFIED
    assert solve_packed(pack.floats, pack.ints, TOL, again) == CERTIFIED
    answer = iterations_at(results[2].r.size) + 1  # r, u, figures, iterations; then work
    assert out[answer - 1] == results[2].iterations
    np.testing.assert_array_equal(out[:answer], results[2]._call[0][:answer])
    np.testing.assert_array_equal(again[:answer], out[:answer])
    np.testing.assert_array_equal(results[1].r, results[2].r)


@pytest.mark.parametrize("solves", [1, 2, 3])
def test_a_solved_problem_pickles_and_solves_as_before(solves: int) -> None:
    """What the route keeps on a problem (its state, its pack) pickles with it, and the copy
    is solved as the problem is."""
    problem = friction_data.load("Rover11211").problem
    for _ in range(solves):
        res = iq.solve_friction(problem, tol=TOL)
    copy = pickle.loads(pickle.dumps(problem))
    for _ in range(3):
        again = iq.solve_friction(copy, tol=TOL)
        np.testing.assert_array_equal(again.r, res.r)
    copy.q[:] = 2.0 * copy.q  # the copy's own q: its pack is made again, the original's kept
    np.testing.assert_allclose(iq.solve_friction(copy, tol=TOL).r, 2.0 * res.r, rtol=1e-12)
    np.testing.assert_array_equal(iq.solve_friction(problem, tol=TOL).r, res.r)


def test_machine_code_is_found_where_there_is_some() -> None:
    """machine_code: a dispatcher with nothing compiled and a plain function are returned as
    they are; once compiled, the machine code for the arguments' types."""
    import numba

    def plain(x):
        return x

    assert machine_code(plain, 1.0) is plain

    @numba.njit
    def twice(x):
        return 2.0 * x

    assert machine_code(twice, 1.0) is twice  # nothing compiled yet
    assert twice(1.5) == 3.0
    code = machine_code(twice, 1.0)
    if numba.config.DISABLE_JIT:  # a plain function: nothing more to find
        assert code is twice
    else:
        assert code is not twice and code(4.0) == 8.0
        assert machine_code(twice, np.ones(2)) is twice  # no code for an array
