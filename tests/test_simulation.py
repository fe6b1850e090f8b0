"""Motion with unilateral contacts (docs/theory.md §14): Moreau–Jean time-stepping against
Siconos' published bouncing ball, event-driven integration against the closed-form impact
times, Newton's cradle on pendulums with the sector law and Moreau's law, the cluster
decomposition against a plain step, saving, the command line and bad input."""

from __future__ import annotations

import importlib
import json

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp.cli as cli
from impactqp.errors import InputError, SectorLawError, ShapeError
from impactqp.laws.complementarity import Fremond, Newton
from impactqp.laws.moreau import Moreau
from impactqp.laws.pipeline import solve
from impactqp.laws.sector import SectorLaw
from impactqp.model.problem import ImpactProblem
from impactqp.qp.lcp import solve_lcp
from impactqp.simulation.builders import bead_chain, bouncing_ball, cradle_system
from impactqp.simulation.clusters import ClusterCache
from impactqp.simulation.simulate import simulate
from impactqp.simulation.step_law import MoreauJeanStep
from impactqp.simulation.system import LinearForce, LinearSystem

# Siconos' BouncingBallTS example, reference output BouncingBallTS.ref: numbers only, a
# subsample of its 2001 records (every 100th step and the steps around the first impacts and
# in the resting phase), as (step, q, v, λ). Source: github.com/siconos/siconos-tutorials,
# examples/mechanics/BouncingBall/BouncingBallTS.ref at commit
# b6c9bfd1940a69dae512a3e39cf5f1a951e3eebe; Siconos is licensed under Apache-2.0.
SICONOS_BOUNCING_BALL = [
    (0, 1.0, 0.0, 0.0),
    (89, 0.02868737499999887, -4.365450000000009, 0.0),
    (90, 0.00673749999999881, -4.414500000000009, 0.0),
    (91, 0.005633874999998808, 3.973050000000009, 8.436600000000018),
    (92, 0.02537649999999887, 3.924000000000008, 0.0),
    (93, 0.04487387499999893, 3.874950000000008, 0.0),
    (100, 0.1744884999999991, 3.531600000000007, 0.0),
    (200, 0.7140385, -1.373399999999999, 0.0),
    (252, 0.02537650000000036, -3.923999999999999, 0.0),
    (253, 0.005633874999999903, -3.97305, 0.0),
    (254, 0.004640612499999924, 3.575745, 7.597845),
    (255, 0.02239671250000033, 3.526694999999999, 0.0),
    (256, 0.03990756249999996, 3.477645, 0.0),
    (300, 0.5675874625000001, 1.319445000000001, 0.0),
    (399, 0.01886511250000029, -3.536505, 0.0),
    (400, 0.00105996250000067, -3.585554999999998, 0.0),
    (401, 0.000163573750000692, 3.226999499999999, 6.861604499999997),
    (402, 0.01617594625000177, 3.177949499999996, 0.0),
    (403, 0.03194306875000141, 3.128899499999997, 0.0),
    (500, 0.3956807012500005, -1.628950500000001, 0.0),
    (600, 0.4229361921250006, -0.3144595499999997, 0.0),
    (700, 0.3381684358375004, 0.3663985950000006, 0.0),
    (800, 0.2648918597162505, 0.4991862645000014, 0.0),
    (900, 0.2232105071871259, 0.1000923619499993, 0.0),
    (1000, 0.151353680262514, -0.7522581257549901, 0.0),
    (1100, 0.04040307868862544, 1.228574418138451, 0.0),
    (1200, 0.06651538446213634, -0.742746976324602, 0.0),
    (1300, 0.04127424435565218, -0.627621550822929, 0.0),
    (1400, 0.02739785245603675, 0.2848801105499127, 0.0),
    (1500, 0.007675139496731129, -0.406428200590878, 0.0),
    (1600, 0.003772093865338502, -0.1007900025002139, 0.0),
    (1680, 8.446348515126726e-05, 0.0423047936764027, 0.1383601199835245),
    (1681, 0.0001733624535332875, -0.006745206323587542, 0.0),
    (1682, 1.701142191530615e-05, -0.05579520632359521, 0.0),
    (1683, 3.062620334405146e-06, 0.05021568569123569, 0.1550608920148386),
    (1684, 0.0001315160487905824, 0.001165685691245442, 0.0),
    (1685, 1.471947724677219e-05, -0.04788431430876223, 0.0),
    (1686, 2.748398669584007e-06, 0.043095882877886, 0.1400301971866385),
    (1687, 9.560281305900936e-05, -0.005954117122121669, 0.0),
    (1688, -5.679277255154428e-05, -0.05500411712211192, 0.0),
    (1689, -7.054380183207438e-05, 0.04950370540990073, 0.1535578225320203),
    (1690, 5.434972521742884e-05, 0.0004537054099104862, 0.0),
    (1691, -6.600674773305672e-05, -0.04859629459009718, 0.0),
    (1700, -2.287556256428868e-05, -8.069939326208614e-05, 0.04887963461421473),
    (1800, -2.288618062346925e-05, -2.143488775363522e-09, 0.04904999547484728),
    (1900, -2.288618090549976e-05, -5.69266855876549e-14, 0.04904999999987007),
    (2000, -2.288618090550717e-05, -2.775557561562891e-17, 0.04904999999999019),
]


@pytest.fixture(scope="module")
def siconos_ball():
    return simulate(bouncing_ball(), Newton(0.9), 10.0, h=0.005, theta=0.5)


@pytest.fixture(scope="module")
def event_ball():
    return simulate(bouncing_ball(), Newton(0.9), 10.0, scheme="event-driven", h=0.01)


def test_moreau_jean_reproduces_siconos_bouncing_ball(siconos_ball):
    tr = siconos_ball
    assert tr.t.size == 2001 and tr.t[-1] == pytest.approx(10.0)
    ref = np.array(SICONOS_BOUNCING_BALL)
    k = ref[:, 0].astype(int)
    np.testing.assert_allclose(tr.t[k], 0.005 * k, atol=1e-13)
    np.testing.assert_allclose(tr.q[k, 0], ref[:, 1], rtol=0, atol=1e-13)
    np.testing.assert_allclose(tr.v[k, 0], ref[:, 2], rtol=0, atol=1e-12)
    np.testing.assert_allclose(tr.impulses[k, 0], ref[:, 3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(tr.generalized_impulses[k, 0], ref[:, 3], rtol=0, atol=1e-12)
    # impulses exactly on the steps with closed contacts, each step certified
    assert np.count_nonzero(tr.impulses[:, 0]) == len(tr.events) == 345
    assert tr.certified and all(e.law == "moreau-jean" for e in tr.events)


def test_step_law_admissibility_is_reported(siconos_ball):
    # the step law is Newton's on γ_k: a contact closed by the prediction while it still
    # separates gets γ⁺ = -eγ_k < 0 (docs/theory.md §14): such steps are certified, not in S
    adm = siconos_ball.admissible()
    assert adm[:20].all() and not adm.all()
    bad = siconos_ball.events[int(np.argmin(adm))]
    assert bad.certified and bad.admissible.failed() == ["kinematic"]


def test_event_driven_bouncing_ball_matches_the_geometric_series(event_ball):
    g, e, q0 = 9.81, 0.9, 1.0
    t1 = np.sqrt(2 * q0 / g)
    v1 = g * t1
    k = np.arange(len(event_ball.events))
    series = t1 + (2 * v1 / g) * e * (1 - e**k) / (1 - e)
    assert len(k) > 100
    np.testing.assert_allclose(event_ball.impact_times, series, rtol=0, atol=1e-9)
    t_inf = t1 * (1 + e) / (1 - e)
    assert 0 < t_inf - event_ball.impact_times[-1] < 1e-6
    after = event_ball.t > t_inf
    assert after.sum() > 100
    assert np.abs(event_ball.q[after]).max() < 1e-12 and np.abs(event_ball.v[after]).max() == 0
    assert event_ball.events[-1].settled.tolist() == [0]
    assert event_ball.certified and event_ball.admissible().all()
    assert event_ball.t[-1] == 10.0


@pytest.mark.parametrize("n", [3, 5])
def test_sector_law_cradle_conserves_energy_and_passes_the_motion_on(n):
    amplitude = 0.1
    tr = simulate(cradle_system(n, amplitude=amplitude), SectorLaw(), 3.2,
                  scheme="event-driven", h=0.01)
    assert tr.energy_drift() < 1e-8
    # at every impact: the same energy before and after (same positions, sorted speeds)
    for e in tr.events:
        rows = np.flatnonzero(tr.t == e.time)
        E = tr.total_energy[rows]
        assert np.ptp(E) <= 1e-12 * E[0]
    first = tr.events[0]
    v = first.u_minus[0]
    assert v == pytest.approx(amplitude * np.sqrt(9.81), rel=1e-9)
    np.testing.assert_allclose(first.u_plus, np.r_[np.zeros(n - 1), v], atol=1e-12)
    between = (tr.t > first.time) & (tr.t < tr.events[1].time)
    assert np.abs(tr.q[between, :-1]).max() < 1e-12
    assert tr.q[between, -1].max() == pytest.approx(amplitude, rel=1e-3)  # on the grid
    np.testing.assert_allclose(tr.events[1].u_plus, np.r_[-v, np.zeros(n - 1)], atol=1e-12)
    assert len(tr.events) == 3 and tr.certified and tr.admissible().all()


@pytest.mark.parametrize("n", [3, 5])
def test_moreau_cradle_spreads_or_moves_together(n):
    elastic = simulate(cradle_system(n), Moreau(1.0), 1.2, scheme="event-driven")
    first = elastic.events[0]
    v = first.u_minus[0]
    np.testing.assert_allclose(first.u_plus, v * np.r_[2 / n - 1, np.full(n - 1, 2 / n)],
                               atol=1e-12)
    assert elastic.energy_drift() < 1e-8
    plastic = simulate(cradle_system(n), Moreau(0.0), 3.0, scheme="event-driven")
    assert len(plastic.events) == 1
    np.testing.assert_allclose(plastic.events[0].u_plus, np.full(n, v / n), atol=1e-12)
    later = plastic.t > plastic.events[0].time
    assert np.ptp(plastic.q[later], axis=1).max() < 1e-12  # one body from then on
    assert np.ptp(plastic.v[later], axis=1).max() < 1e-12
    for tr in (elastic, plastic):
        assert tr.certified and tr.admissible().all()


def test_time_stepping_with_closed_form_and_projecting_laws_stays_in_S():
    for law in (SectorLaw(), Moreau(0.0), Newton(0.0)):
        tr = simulate(cradle_system(3), law, 0.8, h=2e-3)
        assert tr.events and tr.certified and tr.admissible().all(), law
    sector = simulate(cradle_system(3), SectorLaw(), 0.55, h=2e-3)  # just after the impact
    assert sector.energy_drift() < 1e-3
    assert np.abs(sector.v[-1, :2]).max() < 0.02 and sector.v[-1, 2] > 0.25


def test_a_held_contact_lifts_off_when_its_force_turns():
    # resting on the ground under f(t) = g(2t - 1): pressed until t = 1/2, then pulled up,
    # so q(t) = g(t - 1/2)³/3 after the lift-off
    g = 9.81
    system = LinearSystem([[1.0]], [0.0], [0.0], lambda t, q, v: np.array([g * (2 * t - 1)]),
                          [[1.0]])
    tr = simulate(system, Moreau(0.0), 2.0, scheme="event-driven", h=0.1)
    assert tr.settings["events"] == 1 and not tr.events  # a lift-off, no impact
    assert abs(tr.t[np.flatnonzero(tr.q[:, 0] == 0)[-1]] - 0.5) < 1e-8
    later = tr.t > 0.6
    np.testing.assert_allclose(tr.q[later, 0], g * (tr.t[later] - 0.5) ** 3 / 3, rtol=1e-8)


def _plain_moreau_jean(system, e, t_end, h):
    """One LCP per step over all closed contacts (no clusters), as a reference."""
    q, v = system.q0.copy(), system.v0.copy()
    f, M = system.constant_force, np.asarray(system.M.toarray() if sp.issparse(system.M)
                                              else system.M)
    H = np.asarray(system.H.toarray() if sp.issparse(system.H) else system.H)
    for _ in range(int(round(t_end / h))):
        closed = system.gaps(q) + 0.5 * h * system.contact_velocities(v) <= 0
        v_free = v + np.linalg.solve(M, h * f)
        v_next = v_free
        if closed.any():
            A = H[:, closed]
            G = A.T @ np.linalg.solve(M, A)
            lam = solve_lcp(G, A.T @ v_free + e * (A.T @ v)).z
            v_next = v_free + np.linalg.solve(M, A @ lam)
        q = q + h * (0.5 * v + 0.5 * v_next)
        v = v_next
    return q, v


@pytest.mark.parametrize("law", [Newton(0.5), Newton(np.full(12, 0.5)), Fremond(0.5 * np.eye(12))])
def test_clusters_agree_with_one_lcp_per_step(law):
    system = bead_chain(12, height=0.101, spacing=0.2005)
    tr = simulate(system, law, 0.12, h=1e-3)
    q, v = _plain_moreau_jean(system, 0.5, 0.12, 1e-3)
    np.testing.assert_allclose(tr.q[-1], q, atol=1e-12)
    np.testing.assert_allclose(tr.v[-1], v, atol=1e-10)
    sizes = {e.contacts.size for e in tr.events}
    assert len(sizes) > 1 and tr.certified


def test_general_system_with_coupled_mass_matrix():
    # two bodies coupled through M, two walls: one cluster as soon as one contact closes
    M = np.array([[2.0, 0.5], [0.5, 1.0]])
    H = np.array([[1.0, 0.0], [0.0, -1.0]])
    system = LinearSystem(M, [0.2, -0.1], [0.0, 0.0], [-1.0, 1.0], H, [0.0, 0.3])
    ts = simulate(system, Moreau(0.5), 1.5, h=1e-3)
    ed = simulate(system, Moreau(0.5), 1.5, scheme="event-driven")
    for tr in (ts, ed):
        assert tr.events and tr.certified and tr.gaps.min() > -1e-2
        assert all(e.dofs.tolist() == [0, 1] for e in tr.events)
    assert ed.admissible().all() and ed.gaps.min() > -1e-12
    assert np.abs(ts.q[-1] - ed.q[-1]).max() < 0.05


def test_cluster_cache_groups_runs_of_a_chain_and_reuses_structures():
    system = bead_chain(8)
    cache = ClusterCache(system.M, system.H, system.chain)
    closed = np.zeros(8, dtype=bool)
    closed[[0, 1, 4, 5, 7]] = True  # ground+beads 0-1, beads 3-4-5, beads 6-7
    clusters = cache.clusters(closed)
    assert [c.contacts.tolist() for c in clusters] == [[0, 1], [4, 5], [7]]
    assert [c.dof_indices(8).tolist() for c in clusters] == [[0, 1], [3, 4, 5], [6, 7]]
    assert [(c.structure.chain.left_wall, c.structure.n) for c in clusters] == \
        [(True, 2), (False, 3), (False, 2)]
    assert clusters[1].structure is cache.clusters(np.eye(8, dtype=bool)[4] | np.eye(
        8, dtype=bool)[5])[0].structure
    general = ClusterCache(system.M.toarray() if sp.issparse(system.M) else system.M,
                           sp.csc_matrix(system.H), None)
    assert [c.contacts.tolist() for c in general.clusters(closed)] == [[0, 1], [4, 5], [7]]


def test_step_law_forms_agree_and_u_minus_zero_is_still_solved():
    rng = np.random.default_rng(3)
    M = np.diag([1.0, 2.0, 3.0])
    W = np.array([[1.0, -1.0], [0.0, 1.0], [0.5, 0.0]])
    p = ImpactProblem(M, W, rng.standard_normal(3))
    step = MoreauJeanStep(0.7, rng.standard_normal(3))
    a = solve(p, step, form="impulse")
    b = solve(p, step, form="velocity")
    np.testing.assert_allclose(a.u_plus, b.u_plus, atol=1e-10)
    assert a.certificate.ok and b.certificate.ok
    # v_free = 0 exactly with e·γ_k < 0: a step of h = 0.5 under force 2 from v = -1 at q = 0
    system = LinearSystem([[1.0]], [0.0], [-1.0], [2.0], [[1.0]])
    tr = simulate(system, Newton(0.5), 0.5, h=0.5)
    assert tr.impulses[-1, 0] == pytest.approx(0.5) and tr.v[-1, 0] == pytest.approx(0.5)
    assert tr.certified and tr.events[0].result.certificate.ok


def test_forces_energies_and_potentials():
    K = np.array([[2.0, -1.0], [-1.0, 2.0]])
    spring = LinearForce(K, [0.0, -1.0])
    q = np.array([0.3, -0.2])
    assert spring.potential(q) == pytest.approx(0.5 * q @ K @ q - 0.2)
    system = LinearSystem(np.eye(2), q, [0.1, 0.0], spring)
    np.testing.assert_allclose(system.potential_energy(np.vstack([q, q])), spring.potential(q))
    assert simulate(system, Moreau(0.0), 2.0, scheme="event-driven").energy_drift() < 1e-9
    free = LinearSystem(np.eye(1), [1.0], [0.0], lambda t, q, v: -q)
    assert np.isnan(free.potential_energy(np.array([1.0])))
    tr = simulate(LinearSystem(np.eye(1), [1.0], [0.0], lambda t, q, v: -q,
                               potential=lambda q: 0.5 * float(q @ q)), Moreau(0.0), 1.0,
                  h=1e-3)
    assert tr.energy_drift() < 1e-3 and not tr.events


def test_save_npz_and_csv(tmp_path, event_ball):
    tr = simulate(cradle_system(3), SectorLaw(), 1.2, scheme="event-driven", h=0.05)
    data = np.load(tr.save(tmp_path / "run.npz"))
    np.testing.assert_array_equal(data["q"], tr.q)
    np.testing.assert_array_equal(data["event_time"], tr.impact_times)
    assert data["event_certified"].all() and data["event_admissible"].all()
    offsets = data["event_u_plus_offsets"]
    np.testing.assert_array_equal(data["event_u_plus"][offsets[0]:offsets[1]],
                                  tr.events[0].u_plus)
    assert json.loads(str(data["meta"]))["scheme"] == "event-driven"
    tr.save(tmp_path / "run.csv")
    table = np.loadtxt(tmp_path / "run.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(table[:, 1:4], tr.q)
    events = (tmp_path / "run.events.csv").read_text().splitlines()
    assert len(events) == 1 + len(tr.events) and events[1].split(",")[3] == "True"
    with pytest.raises(InputError, match="npz"):
        tr.save(tmp_path / "run.txt")


def test_bad_input_names_the_argument():
    with pytest.raises(ShapeError, match="q0"):
        LinearSystem(np.eye(2), [0.0], [0.0, 0.0])
    with pytest.raises(ShapeError, match="force"):
        LinearSystem(np.eye(2), [0.0, 0.0], [0.0, 0.0], [1.0, 2.0, 3.0])
    with pytest.raises(ShapeError, match=r"force\(0, q0, v0\)"):
        LinearSystem(np.eye(2), [0.0, 0.0], [0.0, 0.0], lambda t, q, v: [1.0])
    with pytest.raises(ShapeError, match="H must have shape"):
        LinearSystem(np.eye(2), [0.0, 0.0], [0.0, 0.0], None, [[1.0]])
    with pytest.raises(ShapeError, match="H column"):
        LinearSystem(np.eye(2), [0.0, 0.0], [0.0, 0.0], None, [[0.0], [0.0]])
    with pytest.raises(ShapeError, match="M must"):
        LinearSystem([1.0, 2.0], [0.0, 0.0], [0.0, 0.0])
    with pytest.raises(InputError, match="chain"):
        LinearSystem(np.eye(2), [0.0, 1.0], [0.0, 0.0], None, [[1.0], [0.0]],
                     chain=cradle_system(2).chain)
    ball = bouncing_ball()
    with pytest.raises(InputError, match="scheme"):
        simulate(ball, Newton(0.9), 1.0, scheme="rk4")
    with pytest.raises(InputError, match="h must be positive"):
        simulate(ball, Newton(0.9), 1.0, h=-0.1)
    with pytest.raises(InputError, match="theta"):
        simulate(ball, Newton(0.9), 1.0, theta=1.5)
    with pytest.raises(InputError, match="t_end"):
        simulate(ball, Newton(0.9), 0.0)
    with pytest.raises(InputError, match="unknown option"):
        simulate(ball, Newton(0.9), 1.0, rest_velocity=1e-6)
    with pytest.raises(InputError, match="law"):
        simulate(ball, "newton", 1.0)
    with pytest.raises(SectorLawError, match="wall"):
        simulate(bead_chain(3), SectorLaw(), 1.0)
    with pytest.raises(ShapeError, match="e must"):
        simulate(bead_chain(3), Newton([0.5, 0.5]), 1.0)
    with pytest.raises(InputError, match="penetrates"):
        simulate(LinearSystem(np.eye(1), [-1.0], [0.0], None, [[1.0]]), Moreau(0.0), 1.0,
                 scheme="event-driven")
    with pytest.raises(InputError, match="amplitude"):
        cradle_system(3, amplitude=-1.0)


CRADLE_FILE = """
[system]
kind = "cradle"
n_balls = 3
[law]
name = "moreau"
eps = 1.0
[simulation]
scheme = "event-driven"
t_end = 0.7
"""


def test_cli_simulate(tmp_path, capsys, monkeypatch):
    from impactqp.cli.commands import simulate as command

    main_module = importlib.import_module("impactqp.cli.main")  # the package exports main()
    if command not in main_module.COMMANDS:  # until the lead registers it in cli/main.py
        monkeypatch.setattr(main_module, "COMMANDS", [*main_module.COMMANDS, command])
    path = tmp_path / "cradle.toml"
    path.write_text(CRADLE_FILE)
    code = cli.main(["simulate", str(path), "--json", "--quiet", "--out",
                     str(tmp_path / "run.npz")])
    report = json.loads(capsys.readouterr().out)
    assert code == 0 and report["events"] == 1 and report["certified"]
    assert report["admissible"] == 1 and (tmp_path / "run.npz").exists()
    assert cli.main(["simulate", str(path), "--scheme", "moreau-jean", "--h", "0.01",
                     "--quiet"]) == 0
    assert "moreau-jean simulation" in capsys.readouterr().out
    path.write_text(CRADLE_FILE.replace("n_balls = 3", "n_balls = 3\nballs = 4"))
    assert cli.main(["simulate", str(path)]) == 2
    assert "unknown key(s) ['balls']" in capsys.readouterr().err
    path.write_text(CRADLE_FILE.replace("eps = 1.0", "eps = 2.0"))
    assert cli.main(["simulate", str(path)]) == 2
    assert "eps" in capsys.readouterr().err


def test_figures(tmp_path, event_ball):
    pytest.importorskip("matplotlib")
    from impactqp.figures.motion import animate_cradle, plot_energy, plot_positions

    assert plot_energy(event_ball, tmp_path / "e.png").stat().st_size > 1000
    cradle = simulate(cradle_system(3), SectorLaw(), 1.0, scheme="event-driven", h=0.05)
    assert plot_positions(cradle, tmp_path / "q.svg").stat().st_size > 1000
    gif = animate_cradle(cradle, tmp_path / "c.gif", frames=4, fps=4)
    assert gif.read_bytes()[:6] == b"GIF89a"
    with pytest.raises(InputError, match="gif"):
        animate_cradle(cradle, tmp_path / "c.png")


def test_a_trajectory_draws_itself(tmp_path, event_ball):
    pytest.importorskip("matplotlib")
    from matplotlib.animation import FuncAnimation
    from matplotlib.figure import Figure

    fig = event_ball.plot()  # positions, not written
    assert isinstance(fig, Figure) and not list(tmp_path.iterdir())
    line = fig.axes[0].get_lines()[-1]
    np.testing.assert_array_equal(line.get_ydata(), event_ball.q[:, 0])
    energy = event_ball.plot("energy", tmp_path / "e.pdf", title="ball")
    assert (tmp_path / "e.pdf").read_bytes()[:4] == b"%PDF"
    assert energy.axes[0].get_title() == "ball"
    np.testing.assert_allclose(energy.axes[0].get_lines()[-1].get_ydata(),
                               event_ball.total_energy)
    cradle = simulate(cradle_system(3), SectorLaw(), 1.0, scheme="event-driven", h=0.05)
    movie = cradle.animate(frames=3)
    assert isinstance(movie, FuncAnimation)
    movie.save(str(tmp_path / "kept.gif"), writer="pillow", fps=3)  # shown, so no warning
    cradle.animate(tmp_path / "c.gif", frames=3, fps=3)
    assert (tmp_path / "c.gif").read_bytes()[:6] == b"GIF89a"
    with pytest.raises(InputError, match="kind"):
        cradle.plot("speeds")
    with pytest.raises(InputError, match="dofs"):
        cradle.plot(dofs=[7])
    with pytest.raises(InputError, match="suffix|end in"):
        cradle.plot(path=tmp_path / "q.txt")
