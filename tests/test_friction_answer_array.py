"""The one array a few-contact solve fills (impactqp/kernels/friction_packed.py's answer_size
and iterations_at, impactqp/laws/friction_small.py): r, u, the certificate's figures and the
iterations, then the call's own work (r̂, û, F and a contact's scratch), so that the
compiled call allocates nothing and returns one integer. Whatever the array held before
the call, the answer is the same and certified apart; the work never reaches the result;
a solve from a pack takes the pack only on the route it was packed for."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from benchmarks import friction_data
from benchmarks.friction_tiny import ONE_SWEEP, TINY
from impactqp.errors import BackendUnsuitableError
from impactqp.kernels.friction_packed import (
    FIGURE_COUNT,
    answer_size,
    iterations_at,
    pack,
    solve_packed,
)
from impactqp.kernels.friction_tiny import CERTIFIED
from impactqp.laws import friction_small
from impactqp.laws.friction_small import SmallFrictionResult
from impactqp.model.friction import certify_friction

TOL = 1e-8
NAMES = ["CubeH8", "FC3D-RR-1c", "FC3D-Example1", "TwoRods1-condensed", "FC2D-00394",
         "LMGC-00046", "Rover4144", "FC2D-00374"]
"""Sliding, sticking and separating contacts, 2-D and 3-D, one sweep, more sweeps, Newton."""


def _packed(name: str):
    """A problem of the set solved three times (so kept packed), and its pack."""
    problem = friction_data.load(name).problem
    results = [iq.solve_friction(problem, tol=TOL) for _ in range(3)]
    return problem, results, problem.__dict__[friction_small._KEPT].packed


def test_the_layout_holds_the_work() -> None:
    """After r, u, the figures and the iterations, room for r̂, û, F (d·m each) and the
    3·d floats of a contact's scratch, for both contact dimensions."""
    for size in (2, 3, 6, 27, 96):
        at = iterations_at(size)
        assert at == 2 * size + FIGURE_COUNT
        assert answer_size(size) - (at + 1) >= 3 * size + 3 * 3


@pytest.mark.parametrize("name", NAMES)
def test_what_the_array_held_before_does_not_change_the_answer(name: str) -> None:
    """The same pack solved into arrays filled with NaN, with ±1e300 and with zeros: the
    same r, u, figures and iterations, bit for bit (the call reads no entry it has not
    written), and the answer the route returned, certified apart."""
    problem, results, packed = _packed(name)
    size = problem.q.size
    answer = iterations_at(size) + 1
    outs = []
    for fill in (np.nan, 1e300, -1e300, 0.0):
        out = np.full(answer_size(size), fill)
        assert solve_packed(packed.floats, packed.ints, TOL, out) == CERTIFIED
        outs.append(out[:answer].copy())
    for out in outs[1:]:
        np.testing.assert_array_equal(out, outs[0])
    np.testing.assert_array_equal(outs[0][:size], results[2].r)
    np.testing.assert_array_equal(outs[0][size:2 * size], results[2].u)
    assert outs[0][answer - 1] == results[2].iterations >= 1
    assert certify_friction(problem, outs[0][:size], outs[0][size:2 * size], tol=TOL).ok


@pytest.mark.parametrize("name", [*TINY, *ONE_SWEEP])
def test_the_result_reads_its_answer_not_the_work(name: str) -> None:
    """Each field a result reads from its array: r and u the problem's (u = W r + q
    recomputed here), the certificate the one recomputed apart, the iterations those the
    first solve (through pack and solve_packed) wrote; the work after them is not r, u or the
    figures."""
    problem = friction_data.load(name).problem
    results = [iq.solve_friction(problem, tol=TOL) for _ in range(3)]
    size = problem.q.size
    for res in results:
        assert type(res) is SmallFrictionResult
        out = res._call[0]
        assert out.size == answer_size(size)
        np.testing.assert_allclose(res.u, problem.velocity(res.r),
                                   atol=1e-12 * max(1.0, np.abs(problem.q).max()))
        cert = certify_friction(problem, res.r, res.u, tol=TOL)
        assert cert.ok and res.certificate.ok
        assert res.error == pytest.approx(cert.error, rel=1e-6, abs=1e-14)
        assert res.iterations == results[0].iterations == int(out[iterations_at(size)])
        assert len(res.certificate.values) == 5


@pytest.mark.parametrize("name", ["FC2D-00394", "LMGC-00046", "Rover4144"])
def test_the_first_solve_writes_its_iterations(name: str) -> None:
    """A first solve (pack, then solve_packed) writes the iterations where the result reads
    them: one where the first sweep alone ends the problem, more where it does not (judged apart by
    the first sweep alone, ``whole`` False, exact on these 2-D and sticking or coupled 3-D
    contacts where one sweep is); the sweeps' count where they end it (LMGC-00046), with
    the Newton steps where those do (Rover4144)."""
    problem = friction_data.load(name).problem
    size = problem.q.size
    W, rows, q, mu, d = friction_small._given(problem)
    steps, sweeps, local, _ = friction_small._budgets(True)
    alone = np.full(answer_size(size), np.nan)
    outcome = solve_packed(*pack(W, rows, q, mu, d, (steps, sweeps, local, False)), TOL, alone)
    assert alone[iterations_at(size)] == 1
    out = np.full(answer_size(size), np.nan)
    assert solve_packed(*pack(W, rows, q, mu, d, (steps, sweeps, local, True)), TOL,
                        out) == CERTIFIED
    its = out[iterations_at(size)]
    assert its == int(its) and (its == 1) == (outcome == CERTIFIED)
    assert certify_friction(problem, out[:size], out[size:2 * size], tol=TOL).ok


def test_a_pack_for_the_first_sweep_is_not_taken_by_the_kernel_method() -> None:
    """A problem of 40 decoupled 2-D contacts, which one sweep solves exactly, is packed
    for the first sweep of ``"nsgs-short"``; asked for the ``"kernel"`` method (at most 32
    contacts) it is refused, as before it was packed, and ``auto`` still answers from its
    pack."""
    rng = np.random.default_rng(4)
    m = 40
    W = np.zeros((2 * m, 2 * m))
    for c in range(m):
        A = rng.standard_normal((2, 2))
        W[2 * c:2 * c + 2, 2 * c:2 * c + 2] = A @ A.T + np.eye(2)
    q = rng.standard_normal(2 * m)
    problem = iq.FrictionContactProblem(W, q, 0.4, contact_dim=2)
    firsts = [iq.solve_friction(problem, tol=TOL) for _ in range(3)]
    kept = problem.__dict__[friction_small._KEPT]
    assert kept.packed is not None and not kept.small
    assert all(type(r) is SmallFrictionResult and r.backend == "nsgs-short" for r in firsts)
    with pytest.raises(BackendUnsuitableError):
        iq.solve_friction(problem, backend="kernel", tol=TOL)
    again = iq.solve_friction(problem, tol=TOL)
    assert type(again) is SmallFrictionResult and again.backend == "nsgs-short"
    np.testing.assert_array_equal(again.r, firsts[2].r)
    assert certify_friction(problem, again.r, again.u, tol=TOL).ok
