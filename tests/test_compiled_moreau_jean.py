"""The compiled Moreau–Jean loop (impactqp/kernels/moreau_jean.py) against the Python loop,
which solves every cluster through iq.solve: the same trajectories to round-off, the same
certified events, Siconos' BouncingBallTS reproduced, corrupted data refused, and the
routing rule (docs/theory.md §14)."""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from test_simulation import SICONOS_BOUNCING_BALL

import impactqp as iq
from impactqp.errors import InputError
from impactqp.kernels.residuals import RESIDUALS, chain_step_residuals, dense_step_residuals
from impactqp.simulation import time_stepping
from impactqp.simulation.step_law import MoreauJeanStep
from impactqp.simulation.time_stepping import compiled_applies, moreau_jean

SYSTEMS = {
    "ball": (lambda: iq.simulation.bouncing_ball(), 0.005, 2.5),
    "cradle3": (lambda: iq.simulation.cradle_system(3), 1e-3, 0.7),
    "cradle5": (lambda: iq.simulation.cradle_system(5, released=2), 1e-3, 0.7),
    "beads10": (lambda: iq.simulation.bead_chain(10), 1e-3, 0.6),
}


def _fremond(m: int) -> np.ndarray:
    """A full Frémond matrix: 0.5 on the diagonal, 0.1 between neighbouring contacts."""
    return 0.5 * np.eye(m) + 0.1 * (np.eye(m, k=1) + np.eye(m, k=-1))


LAWS = {
    "newton": lambda m: iq.Newton(0.9),
    "newton-per-contact": lambda m: iq.Newton(np.linspace(0.6, 0.95, m)),
    "moreau": lambda m: iq.Moreau(0.5),
    "fremond": lambda m: iq.Fremond(_fremond(m)),
}


@cache
def _system(name: str) -> iq.LinearSystem:
    return SYSTEMS[name][0]()


@cache
def _run(name: str, law: str, theta: float, compiled: bool, record_every: int = 1):
    system = _system(name)
    _, h, t_end = SYSTEMS[name]
    return moreau_jean(system, LAWS[law](system.n_contacts), t_end, h, theta,
                       record_every=record_every, compiled=compiled)


def _close(a: np.ndarray, b: np.ndarray, scale: float | None = None) -> None:
    """a = b to 1e-12 relative to the largest entry of b (or to ``scale``)."""
    scale = max(np.abs(b).max(), 1e-300) if scale is None else scale
    assert np.abs(a - b).max() <= 1e-12 * scale


def _significant(events, scale: float) -> list:
    """The events whose impulses are more than round-off of the run's largest impulse."""
    return [e for e in events if np.abs(e.impulses).max() > 1e-12 * scale]


@pytest.mark.parametrize("record_every", [1, 7])
@pytest.mark.parametrize("theta", [0.5, 1.0])
@pytest.mark.parametrize("law", list(LAWS))
@pytest.mark.parametrize("name", list(SYSTEMS))
def test_compiled_loop_equals_the_python_loop(name, law, theta, record_every):
    fast = _run(name, law, theta, True, record_every)
    slow = _run(name, law, theta, False)
    assert fast.settings["loop"] == "compiled" and slow.settings["loop"] == "python"
    steps = slow.settings["steps"]
    rows = np.unique(np.append(np.arange(0, steps + 1, record_every), steps))
    np.testing.assert_array_equal(fast.t, slow.t[rows])
    _close(fast.q, slow.q[rows])
    _close(fast.v, slow.v[rows])
    _close(fast.impulses, slow.impulses[rows], np.abs(slow.impulses).max())
    assert {k: v for k, v in fast.settings.items() if k != "loop"} == \
        {k: v for k, v in slow.settings.items() if k not in ("loop", "record_every")} | \
        {"record_every": record_every}
    # the same impacts, each certified with the step law's residuals; the compiled LCP may
    # also solve a cluster whose q is negative by round-off only (Λ of round-off size)
    scale = np.abs(slow.impulses).max()
    mine, theirs = _significant(fast.events, scale), _significant(slow.events, scale)
    assert len(mine) == len(theirs) > 0
    for a, b in zip(mine, theirs):
        assert a.time == b.time and a.kind == b.kind == "step" and a.law == b.law
        np.testing.assert_array_equal(a.contacts, b.contacts)
        np.testing.assert_array_equal(a.dofs, b.dofs)
        _close(a.u_plus, b.u_plus, np.abs(slow.v).max())  # relative to the run's velocities
        _close(a.u_minus, b.u_minus, np.abs(slow.v).max())
        np.testing.assert_allclose(a.impulses, b.impulses, rtol=0, atol=1e-12 * scale)
        assert a.certified and sorted(a.certificate.values) == sorted(b.certificate.values)
        assert a.result.backend == time_stepping.LOOP_BACKEND
        np.testing.assert_array_equal(np.shape(a.result.impact_law.E),
                                      np.shape(b.result.impact_law.E))
    assert fast.certified and slow.certified
    np.testing.assert_array_equal([bool(e.admissible) for e in mine],
                                  [bool(e.admissible) for e in theirs])


def test_compiled_loop_reproduces_siconos_bouncing_ball():
    tr = iq.simulate(iq.simulation.bouncing_ball(), iq.Newton(0.9), 10.0, h=0.005, theta=0.5)
    assert tr.settings["loop"] == "compiled" and tr.t.size == 2001
    ref = np.array(SICONOS_BOUNCING_BALL)
    k = ref[:, 0].astype(int)
    for mine, theirs in ((tr.q[k, 0], ref[:, 1]), (tr.v[k, 0], ref[:, 2]),
                         (tr.impulses[k, 0], ref[:, 3])):
        np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-12 * np.abs(theirs).max())
    assert np.count_nonzero(tr.impulses[:, 0]) == len(tr.events) == 345
    assert tr.certified and all(e.law == "moreau-jean" for e in tr.events)


def test_events_are_kept_or_not_without_changing_the_run():
    system = _system("beads10")
    kept = moreau_jean(system, iq.Newton(0.9), 0.6, 1e-3, keep_events=True)
    bare = moreau_jean(system, iq.Newton(0.9), 0.6, 1e-3, keep_events=False)
    assert bare.events == [] and len(kept.events) > 10 + 64  # more than the first buffers hold
    np.testing.assert_array_equal(kept.q, bare.q)
    np.testing.assert_array_equal(kept.impulses, bare.impulses)
    times = kept.impact_times
    assert np.all(np.diff(times) >= 0)
    assert kept.event_arrays()["event_certified"].all()


def _corrupt(monkeypatch, which: str) -> None:
    """Scale one of the kernel's formed impact arrays (Ŵ⁻¹H or HᵀŴ⁻¹H) by 2 after they are
    built: every answer computed from it is wrong."""
    original = time_stepping._CompiledLoop.__init__

    def corrupted(self, *args, **kwargs):
        original(self, *args, **kwargs)
        self.contacts = self.contacts._replace(**{which: 2.0 * getattr(self.contacts, which)})

    monkeypatch.setattr(time_stepping._CompiledLoop, "__init__", corrupted)


@pytest.mark.parametrize("which", ["MinvH", "G"])
def test_a_corrupted_compiled_step_is_solved_again_by_the_python_loop(monkeypatch, which):
    # one coefficient per contact: the LCP search path (one coefficient on a chain takes
    # the isotonic projection, which reads neither array)
    slow = _run("beads10", "newton-per-contact", 0.5, False)
    _corrupt(monkeypatch, which)
    fast = _run.__wrapped__("beads10", "newton-per-contact", 0.5, True)
    assert fast.settings["loop"] == "compiled"
    _close(fast.q, slow.q)
    _close(fast.v, slow.v)
    # no corrupted answer passed its certificate: every event is the Python loop's
    assert len(fast.events) == len(slow.events) > 0
    assert all(e.result.backend != time_stepping.LOOP_BACKEND and e.certified
               for e in fast.events)


def test_progress_is_reported_at_the_same_times():
    def times(compiled: bool) -> list[float]:
        seen: list[float] = []
        moreau_jean(_system("ball"), iq.Newton(0.9), 2.0, 0.005, compiled=compiled,
                    progress=seen.append)
        return seen

    fast, slow = times(True), times(False)
    assert len(fast) == 200
    np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-12)


class MyNewton(iq.Newton):
    """A user's law: a subclass may change anything, so it takes the Python loop."""


@pytest.mark.parametrize("case", ["callable force", "user law", "sector law", "backend",
                                  "sparse"])
def test_routing_rule(case):
    ball = iq.simulation.bouncing_ball()
    system, law, backend = ball, iq.Newton(0.9), "auto"
    if case == "callable force":
        system = iq.LinearSystem(ball.M, ball.q0, ball.v0, lambda t, q, v: [-9.81], ball.H,
                                 ball.b)
    elif case == "user law":
        law = MyNewton(0.9)
    elif case == "sector law":
        system, law = iq.simulation.cradle_system(3), iq.SectorLaw()
    elif case == "backend":
        backend = "clarabel"
    else:
        system = iq.simulation.cradle_system(3, sparse=True)
    assert not compiled_applies(system, law, backend)
    tr = iq.simulate(system, law, 0.05, h=0.005, backend=backend)
    assert tr.settings["loop"] == "python"
    with pytest.raises(InputError, match="compiled loop"):
        moreau_jean(system, law, 0.05, 0.005, backend=backend, compiled=True)
    assert compiled_applies(ball, iq.Newton(0.9), "auto")


@pytest.mark.parametrize("seed", range(4))
def test_step_residuals_are_the_step_law_certificate(seed):
    # the kernel's certificate of a step (dense_step_residuals, restitution on γ_k) against
    # the step law's own certificate in the Python loop (numpy products), on random steps
    rng = np.random.default_rng(seed)
    n, m = 5, 3
    A = rng.normal(size=(n, n))
    M, W = A @ A.T + n * np.eye(n), rng.normal(size=(n, m))
    problem = iq.ImpactProblem(M, W, rng.normal(size=n))
    E = np.diag(rng.uniform(0, 1, m)) + 0.05 * rng.normal(size=(m, m))
    law = MoreauJeanStep(E, rng.normal(size=n))
    result = iq.solve(problem, law)
    st = problem.structure
    out, work = np.empty(6), np.empty(2 * n + 2 * m)
    dense_step_residuals(st.dense_mass, st.dense_Wt, st.dense_Minv_W, st.contact_scale,
                         problem.u_minus, result.u_plus, result.impulses, law.v_previous, E,
                         0.0, False, out, work)
    mine = dict(zip(RESIDUALS[:4], out[:4]))
    theirs = law.residuals(st, problem.u_minus, result.u_plus, result.impulses)
    for name, value in mine.items():
        assert value == pytest.approx(float(theirs[name]), rel=1e-9, abs=1e-15)
    # and a wrong answer fails both
    wrong = result.u_plus + 1e-3
    dense_step_residuals(st.dense_mass, st.dense_Wt, st.dense_Minv_W, st.contact_scale,
                         problem.u_minus, wrong, result.impulses, law.v_previous, E, 0.0,
                         False, out, work)
    assert out[0] > 1e-6 and float(law.residuals(st, problem.u_minus, wrong,
                                                 result.impulses)["momentum"]) > 1e-6


def _coupled_system(linear: bool) -> iq.LinearSystem:
    """Two bodies of two coupled degrees of freedom each (a full 2 × 2 block of M), each on
    the ground, and a contact between them: clusters by the graph of M and H, not a chain."""
    M = np.zeros((4, 4))
    M[:2, :2] = [[2.0, 0.3], [0.3, 1.0]]
    M[2:, 2:] = [[1.5, -0.2], [-0.2, 1.0]]
    H = np.zeros((4, 3))
    H[0, 0] = H[2, 1] = 1.0
    H[3, 2], H[1, 2] = 1.0, -1.0
    f = -9.81 * M.sum(axis=1)
    force = iq.LinearForce(np.diag([0.0, 30.0, 0.0, 30.0]), f) if linear else f
    return iq.LinearSystem(M, [0.2, 0.7, 0.3, 1.2], [0.0, 1.0, -1.0, 0.0], force, H,
                           [0.0, 0.0, -0.3])


@pytest.mark.parametrize("law", [iq.Newton([0.8, 0.5, 0.9]), iq.Moreau(0.3),
                                 iq.Fremond(_fremond(3))], ids=["newton", "moreau", "fremond"])
@pytest.mark.parametrize("linear", [False, True], ids=["constant", "linear"])
def test_coupled_dense_system(law, linear):
    system = _coupled_system(linear)
    fast = moreau_jean(system, law, 1.0, 1e-3, compiled=True)
    slow = moreau_jean(system, law, 1.0, 1e-3, compiled=False)
    _close(fast.q, slow.q)
    _close(fast.v, slow.v)
    _close(fast.impulses, slow.impulses)
    scale = np.abs(slow.impulses).max()
    mine, theirs = _significant(fast.events, scale), _significant(slow.events, scale)
    assert len(mine) == len(theirs) > 10
    assert {tuple(e.contacts) for e in mine} == {tuple(e.contacts) for e in theirs}
    assert any(e.contacts.size == 1 for e in mine)  # one body alone on the ground
    for a, b in zip(mine, theirs):
        assert a.time == b.time
        np.testing.assert_array_equal(a.dofs, b.dofs)
        np.testing.assert_array_equal(a.contacts, b.contacts)


@pytest.mark.parametrize("walls", [(True, False), (False, False), (True, True)])
def test_chain_step_residuals_are_the_step_law_certificate(walls):
    # the chain pass with the restitution on γ_k against the step law's own certificate,
    # on a right and on a wrong answer of a step of a chain
    rng = np.random.default_rng(7)
    left, right = walls
    problem = iq.chain(rng.uniform(0.5, 2.0, 6), rng.normal(size=6), left_wall=left,
                       right_wall=right)
    st, e = problem.structure, 0.7
    law = MoreauJeanStep(e, rng.normal(size=6))
    result = iq.solve(problem, law)
    masses = st.chain.masses
    for up, ok in ((result.u_plus, True), (result.u_plus + 1e-3, False)):
        out = np.empty(6)
        chain_step_residuals(problem.u_minus, up, result.impulses, law.v_previous, masses,
                             1.0 / masses, st.contact_scale, left, right, e, 0.0, False, out)
        theirs = law.residuals(st, problem.u_minus, up, result.impulses)
        for i, name in enumerate(RESIDUALS[:4]):
            assert out[i] == pytest.approx(float(theirs[name]), rel=1e-9, abs=1e-15)
        assert (max(out[:4]) <= 1e-9) == ok


def test_the_step_rules_are_written_once():
    """The activation rule g + h/2 γ ≤ 0 and the step's q = γ(v_free) + Eγ_k live in
    impactqp/kernels/step.py only; every loop calls them (docs/theory.md §17)."""
    import re
    from pathlib import Path

    package = Path(iq.__file__).parent
    activation = re.compile(r"0\.5 \* h\)?\s*\*")
    found = sorted(str(p.relative_to(package)) for p in package.rglob("*.py")
                   if activation.search(p.read_text(encoding="utf-8")))
    assert found == ["kernels/step.py"]


@pytest.mark.parametrize("d", [1, 3])
def test_step_q_and_the_local_gather_against_numpy(d):
    from impactqp.kernels.step import activation, gather_local, step_q
    from impactqp.kernels.units import contact_units

    rng = np.random.default_rng(d)
    m, C = 5, np.array([0, 2, 3])
    gamma_free, gamma_k = rng.normal(size=C.size * d), rng.normal(size=m)
    e, E = rng.uniform(0, 1, m), _fremond(m)
    for args, restitution in (((e, np.zeros((0, 0))), e[C] * gamma_k[C]),
                              ((np.zeros(0), E), E[np.ix_(C, C)] @ gamma_k[C])):
        q = np.empty(C.size * d)
        approaching = step_q(gamma_free, gamma_k, *args, C, d, q)
        expected = gamma_free.copy()
        expected[::d] += restitution
        np.testing.assert_allclose(q, expected, rtol=1e-15, atol=1e-15)
        assert approaching == bool(np.any(expected[::d] < 0))
    A = rng.normal(size=(m * d, m * d))
    G = A @ A.T
    units = contact_units(np.diag(G).copy(), d)
    cols = (C[:, None] * d + np.arange(d)).ravel()
    W, qt = gather_local(G, units, cols, q, np.empty((cols.size, cols.size)),
                         np.empty(cols.size))
    s = units[cols]
    np.testing.assert_array_equal(W, G[np.ix_(cols, cols)] / np.outer(s, s))
    np.testing.assert_array_equal(qt, q / s)
    assert np.allclose(np.diag(W)[::d], 1.0)  # each contact's normal in its own unit
    g, gamma = np.array([1e-3, -1e-9, 0.0]), np.array([-1.0, 0.0, 1e-3])
    closed = np.empty(3, dtype=bool)
    assert activation(g, gamma, 0.01, closed) == 2
    np.testing.assert_array_equal(closed, g + 0.005 * gamma <= 0)
