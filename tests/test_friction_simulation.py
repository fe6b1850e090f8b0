"""Moreau–Jean time-stepping with Coulomb friction (docs/theory.md §17) against closed forms:
the discrete motion of the scheme, derived by hand, and the continuous motion it converges
to, for a block on an incline, a sphere sliding into rolling, oblique bounces and a sliding
box; μ = 0 against the frictionless loop; energy; refusals by name."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp.simulation.friction_loop as friction_loop
import impactqp.simulation.friction_step as friction_step
from impactqp.errors import CertificateError, InputError, ShapeError
from impactqp.kernels.moreau_jean import DONE, FAILED
from impactqp.laws.complementarity import Newton
from impactqp.laws.coulomb import Coulomb
from impactqp.simulation.builders import (
    block_on_incline,
    bouncing_ball,
    box_on_floor,
    rolling_sphere,
)
from impactqp.simulation.event_driven import event_driven
from impactqp.simulation.friction_step import FrictionEvent
from impactqp.simulation.simulate import simulate
from impactqp.simulation.system import LinearForce, LinearSystem
from impactqp.simulation.time_stepping import moreau_jean

G = 9.81
OVERLAP = -1e-9  # a resting contact starts closed for the activation rule (docs/theory.md §17)


@pytest.fixture(params=["friction-compiled", "friction"])
def loop(request) -> str:
    """The compiled frictional loop (the default route) and the Python one."""
    return request.param


def run(system, law, t_end, loop, **kwargs):
    """``simulate`` through the default route, which must be the compiled frictional loop,
    or through the Python frictional loop."""
    if loop == "friction":
        h, theta = kwargs.pop("h"), kwargs.pop("theta", 0.5)
        tr = moreau_jean(system, law, t_end, h, theta, compiled=False, **kwargs)
    else:
        tr = simulate(system, law, t_end, **kwargs)
    assert tr.settings["loop"] == loop
    return tr


def up_slope(angle: float, dim: int) -> np.ndarray:
    return np.array([np.cos(angle), np.sin(angle)]) if dim == 2 else \
        np.array([np.cos(angle), 0.0, np.sin(angle)])


# --- (a) a block on an incline ----------------------------------------------------------------
@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("angle, mu", [(0.4, 0.2), (0.4, 0.5), (0.3, np.tan(0.3)),
                                       (1.2, 0.05), (0.2, 0.0)])
@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_block_on_an_incline_sticks_or_slides_as_the_closed_form(dim, angle, mu, theta, loop):
    h, t_end = 0.01, 1.0
    system = block_on_incline(angle, dim=dim, gap=OVERLAP, twist=0.7)
    tr = run(system, Coulomb(mu), t_end, loop, h=h, theta=theta)
    assert tr.certified
    a = G * max(0.0, np.sin(angle) - mu * np.cos(angle))  # down the slope
    up = up_slope(angle, dim)
    s, x = tr.v @ up, tr.q @ up
    # the scheme's own motion (docs/theory.md §17): s_k = −a t_k, x_k = −a t_k²/2 − a h t_k (θ − ½)
    assert np.allclose(s, -a * tr.t, rtol=0, atol=1e-12)
    assert np.allclose(x, -0.5 * a * tr.t**2 - a * h * tr.t * (theta - 0.5), rtol=0,
                       atol=1e-12)
    # the continuous motion, to O(h), and no motion off the slope
    assert np.abs(x + 0.5 * a * tr.t**2).max() <= a * h * t_end * abs(theta - 0.5) + 1e-12
    assert np.abs(tr.gaps - OVERLAP).max() < 1e-12
    if dim == 3:
        assert np.abs(tr.v[:, 1]).max() < 1e-12
    if a == 0.0:
        assert mu >= np.tan(angle) * (1 - 1e-12) and np.abs(tr.q - tr.q[0]).max() < 1e-12
    assert len(tr.events) == round(t_end / h)  # every step is a certified local problem


@pytest.mark.parametrize("dim", [2, 3])
def test_a_block_sliding_down_a_gentle_slope_stops_and_sticks(dim, loop):
    angle, mu, s0, h = 0.2, 0.6, -2.0, 0.01
    tr = run(block_on_incline(angle, dim=dim, speed=s0, gap=OVERLAP), Coulomb(mu), 1.5, loop,
             h=h)
    b = G * (mu * np.cos(angle) - np.sin(angle))  # deceleration while sliding down
    s = tr.v @ up_slope(angle, dim)
    exact = np.minimum(s0 + b * tr.t, 0.0)
    miss = np.abs(s - exact)
    assert miss.max() <= b * h + 1e-12  # only the step that stops differs, by < bh
    assert np.count_nonzero(miss > 1e-12) <= 1
    t_stop = -s0 / b
    assert np.abs(s[tr.t > t_stop + h]).max() < 1e-12  # stuck for good


# --- (c) a sphere sliding into rolling -----------------------------------------------------
@pytest.mark.parametrize("mu, v0, omega0", [(0.3, 2.0, 0.0), (0.1, 1.0, 0.0),
                                            (0.3, 2.0, 40.0), (0.3, 2.0, 100.0)])
def test_a_sliding_sphere_rolls_at_five_sevenths_after_two_v0_over_seven_mu_g(mu, v0, omega0,
                                                                             loop):
    R, h, t_end = 0.1, 1e-3, 1.5
    tr = run(rolling_sphere(radius=R, velocity=v0, spin=omega0, gap=OVERLAP), Coulomb(mu),
             t_end, loop, h=h)
    slip = tr.v[:, 0] + R * tr.v[:, 2]
    w0 = v0 + R * omega0
    t_star = abs(w0) / (3.5 * mu * G)  # 2v0/(7μg) without spin
    rolling = (5.0 * v0 - 2.0 * R * omega0) / 7.0  # 5/7 v0 without spin
    # the scheme: the slip falls by 7/2 μ g h a step until the step that stops it
    sliding = tr.t < t_star - h
    assert np.allclose(slip[sliding], w0 - 3.5 * mu * G * tr.t[sliding], rtol=0, atol=1e-11)
    assert np.abs(slip[tr.t >= t_star]).max() < 1e-11
    k = int(np.argmax(np.abs(slip) < 1e-11))
    assert t_star <= tr.t[k] < t_star + h
    # v − (2/5)Rω is conserved exactly, so the rolling speed is the continuous one
    assert np.allclose(tr.v[:, 0] - 0.4 * R * tr.v[:, 2], v0 - 0.4 * R * omega0, atol=1e-12)
    after = tr.t >= t_star
    assert np.allclose(tr.v[after, 0], rolling, atol=1e-11)
    assert np.allclose(tr.v[after, 2], -rolling / R, atol=1e-10)
    # positions: x(t) of the continuous motion to O(h)
    x = np.where(tr.t < t_star, v0 * tr.t - 0.5 * mu * G * np.sign(w0) * tr.t**2,
                 v0 * t_star - 0.5 * mu * G * np.sign(w0) * t_star**2
                 + rolling * (tr.t - t_star))
    assert np.abs(tr.q[:, 0] - x).max() < 2 * mu * G * h * t_end
    assert np.abs(tr.q[:, 1] - R - OVERLAP).max() < 1e-12


# --- (b) oblique bounces ------------------------------------------------------------------
def _first_impact(tr):
    """Index k of the first step with an impulse: v[k] = v_k, v[k + 1] = v_{k+1}."""
    return int(np.argmax(np.abs(tr.impulses).sum(axis=1) > 0)) - 1


@pytest.mark.parametrize("mu, e, vx, omega, regime", [
    (0.2, 0.5, 1.0, 0.0, "stick"), (0.05, 0.5, 3.0, 0.0, "slip"),
    (0.3, 1.0, -2.0, 120.0, "slip"), (0.5, 0.0, 0.5, -10.0, "stick"),
])
def test_an_oblique_bounce_of_a_sphere_sticks_or_slips_as_the_closed_form(mu, e, vx, omega,
                                                                         regime, loop):
    R, m, h = 0.1, 2.0, 1e-3
    tr = run(rolling_sphere(mass=m, radius=R, velocity=vx, spin=omega, height=0.5),
             Coulomb(mu, e), 0.5, loop, h=h)
    k = _first_impact(tr)
    (x, y, w), after = tr.v[k], tr.v[k + 1]
    assert y < 0
    P = m * ((1.0 + e) * -y + h * G)  # normal impulse: u_n = γ_{k+1} + eγ_k = 0
    slip = x + R * w
    sticks = abs(slip) <= 3.5 * mu * P / m  # W_tt = 1/m + R²/I = 7/(2m)
    assert sticks == (regime == "stick")
    r_t = -slip * m / 3.5 if sticks else -mu * P * np.sign(slip)
    expected = [x + r_t / m, -e * y, w + 2.5 * r_t / (m * R)]
    assert np.allclose(after, expected, rtol=1e-12, atol=1e-12)
    assert np.allclose(tr.impulses[k + 1], [P, r_t], rtol=1e-12, atol=1e-12)
    if sticks:
        assert abs(after[0] + R * after[2]) < 1e-12
    # the classical impact (h → 0): Δvx = −μ(1 + e)|vy| in slip, rolling in stick
    classical = x - 2.0 / 7.0 * slip if sticks else x - mu * (1 + e) * -y * np.sign(slip)
    assert abs(after[0] - classical) <= mu * G * h + 1e-12


@pytest.mark.parametrize("mu, e, vx", [(0.2, 0.8, 1.0), (0.2, 0.8, 10.0), (0.0, 1.0, 3.0)])
def test_an_oblique_bounce_of_a_point_mass_loses_mu_1_plus_e_vy(mu, e, vx, loop):
    h = 1e-3
    tr = run(block_on_incline(0.0, speed=vx, gap=0.3), Coulomb(mu, e), 0.5, loop, h=h)
    k = _first_impact(tr)
    (x, y), after = tr.v[k], tr.v[k + 1]
    drop = mu * ((1.0 + e) * -y + h * G)
    assert np.allclose(after, [max(x - drop, 0.0), -e * y], rtol=1e-12, atol=1e-12)


# --- several contacts: a box sliding flat -------------------------------------------------
@pytest.mark.parametrize("dim, velocity", [(2, 3.0), (3, (2.0, 1.5))])
def test_a_box_on_its_corners_slides_to_a_stop_at_mu_g(dim, velocity, loop):
    mu, h = 0.4, 0.01
    tr = run(box_on_floor(dim, velocity=velocity, gap=OVERLAP), Coulomb(mu), 1.0, loop, h=h)
    v0 = np.linalg.norm(velocity)
    horizontal = tr.v[:, :dim - 1]
    speed = np.linalg.norm(horizontal, axis=1)
    exact = np.maximum(v0 - mu * G * tr.t, 0.0)
    moving = tr.t < v0 / (mu * G) - h
    # rank-deficient W (more contact rows than degrees of freedom): velocities to the
    # certificate's tolerance, not to round-off
    assert np.allclose(speed[moving], exact[moving], rtol=0, atol=1e-8)
    assert np.abs(speed[tr.t > v0 / (mu * G)]).max() < 1e-8
    direction = horizontal[moving] / speed[moving, None]
    assert np.allclose(direction, np.asarray(velocity) / v0, atol=1e-8)
    assert np.abs(tr.v[:, dim - 1:]).max() < 1e-7  # flat: no vertical motion or rotation
    assert all(len(ev.contacts) == 2 ** (dim - 1) for ev in tr.events)


# --- a spring: stick-slip through the iteration matrix M + h²θ²K -----------------------------
def _spring_block(sparse: bool) -> LinearSystem:
    m, k = 2.0, 50.0
    M, K = np.diag([m, m]), np.diag([k, 0.0])
    H = np.array([[0.0, 1.0], [1.0, 0.0]])  # floor normal (y), then the tangent (x)
    if sparse:
        M, K, H = sp.csc_matrix(M), sp.csr_matrix(K), sp.csc_matrix(H)
    return LinearSystem(M, [0.5, 0.0], [0.0, 0.0], LinearForce(K, [0.0, -m * G]), H,
                        [OVERLAP], contact_dim=2)


def _coulomb_oscillator(t: float, x0: float, omega: float, xe: float) -> float:
    """A mass on a spring with dry friction, released at rest: half cycles about ±xe, each
    shorter by 2xe in amplitude, until it stops within |x| ≤ xe."""
    a = x0
    while abs(a) > xe:
        centre = np.sign(a) * xe
        if t <= np.pi / omega:
            return centre + (a - centre) * np.cos(omega * t)
        a, t = 2.0 * centre - a, t - np.pi / omega
    return a


@pytest.mark.parametrize("h", [1e-2, 1e-3])
def test_a_block_on_a_spring_slows_by_four_mu_g_over_omega_squared_a_cycle(h, loop):
    m, k, mu, x0 = 2.0, 50.0, 0.3, 0.5
    omega, xe = np.sqrt(k / m), mu * m * G / k
    tr = run(_spring_block(False), Coulomb(mu), 3.0, loop, h=h)
    exact = np.array([_coulomb_oscillator(t, x0, omega, xe) for t in tr.t])
    assert np.abs(tr.q[:, 0] - exact).max() < 0.5 * h
    halves = np.ceil((x0 - xe) / (2 * xe))  # half cycles until |x| ≤ xe (two here)
    final = (-1) ** halves * (x0 - 2 * xe * halves)
    assert abs(tr.q[-1, 0] - final) < 10 * h**2 and abs(tr.v[-1, 0]) < 1e-12
    sparse = run(_spring_block(True), Coulomb(mu), 3.0, "friction", h=h)  # no compiled loop
    assert np.abs(sparse.q - tr.q).max() < 1e-10 and sparse.certified


# --- μ = 0 is the frictionless loop ---------------------------------------------------------
def _normal_columns(system: LinearSystem) -> LinearSystem:
    d = system.contact_dim
    return LinearSystem(system.M, system.q0, system.v0, system.constant_force,
                        system.H[:, ::d], system.b)


@pytest.mark.parametrize("system, e, t_end", [
    (rolling_sphere(velocity=1.0, spin=3.0, height=0.3), 0.6, 0.6),
    (block_on_incline(0.5, speed=1.0, gap=OVERLAP), 0.0, 1.0),
    (box_on_floor(3, velocity=(1.0, 0.5), gap=0.05), 0.5, 0.5),
    (box_on_floor(2, velocity=1.0, gap=0.05), 0.0, 0.5),
])
def test_without_friction_the_step_is_newtons(system, e, t_end, loop):
    """To round-off with the certificate's tolerance at round-off (the boxes' W is singular:
    at tol, their velocities agree to about tol·‖q‖)."""
    h = 1e-3
    rough = run(system, Coulomb(0.0, e), t_end, loop, h=h, tol=1e-14)
    smooth = simulate(_normal_columns(system), Newton(e), t_end, h=h, tol=1e-14)
    assert len(rough.events) == len(smooth.events) > 0
    scale = np.abs(smooth.v).max()
    assert np.abs(rough.v - smooth.v).max() <= 1e-12 * scale
    assert np.abs(rough.q - smooth.q).max() <= 1e-12 * scale * t_end
    d = system.contact_dim  # Λ is not unique where W is singular; HΛ is
    impulses = np.abs(smooth.generalized_impulses).max()
    assert np.abs(rough.generalized_impulses - smooth.generalized_impulses).max() \
        <= 1e-12 * impulses
    tangents = np.delete(rough.impulses, np.s_[::d], axis=1)
    assert np.abs(tangents).max() <= 1e-12 * impulses  # μ = 0: no tangent impulse


# --- energy -------------------------------------------------------------------------------
@pytest.mark.parametrize("seed", range(4))
def test_energy_never_grows_beyond_the_schemes_own_bound(seed, loop):
    """A bouncing, sliding, spinning sphere: friction never adds energy; the normal step adds
    at most (1 − e)/(1 + e) m(hg)²/8, on a step that closes a separating contact, and nothing
    at all for e = 1 (docs/theory.md §17)."""
    rng = np.random.default_rng(seed)
    mu, e = rng.uniform(0.0, 0.8), [0.0, 0.4, 0.9, 1.0][seed]
    m, h = rng.uniform(0.5, 2.0), 1e-3
    system = rolling_sphere(mass=m, velocity=rng.uniform(-3, 3), spin=rng.uniform(-50, 50),
                            height=rng.uniform(0.15, 0.5), vertical_velocity=rng.uniform(-2, 2))
    tr = run(system, Coulomb(mu, e), 1.0, loop, h=h)
    E = tr.total_energy
    bound = (1 - e) / (1 + e) * m * (h * G) ** 2 / 8
    assert np.diff(E).max() <= bound + 1e-12 * abs(E).max()
    assert E[-1] <= E[0] + 1e-12 * abs(E).max()


def test_events_are_certified_and_their_steps_admissible_with_e_0(loop):
    tr = run(box_on_floor(3, velocity=(1.0, -0.5), gap=0.01), Coulomb(0.3), 0.4, loop, h=1e-3)
    assert tr.events and all(isinstance(ev, FrictionEvent) for ev in tr.events)
    assert all(ev.certificate.ok and ev.certificate.error <= 1e-9 for ev in tr.events)
    assert tr.admissible().all()  # e = 0: u⁺ in S of each step, r the witness
    assert tr.impulses.shape == (tr.t.size, 12)
    assert "certificates: all ok" in tr.summary()


# --- refusals -----------------------------------------------------------------------------
def test_frictional_systems_are_checked_by_name():
    M, H = np.eye(2), np.eye(2)
    with pytest.raises(InputError, match="contact_dim must be one of"):
        LinearSystem(M, [0, 0], [0, 0], None, H, contact_dim=4)
    with pytest.raises(ShapeError, match="contact_dim = 2 columns per contact"):
        LinearSystem(M, [0, 0], [0, 0], None, np.ones((2, 3)), contact_dim=2)
    with pytest.raises(ShapeError, match="b"):
        LinearSystem(M, [0, 0], [0, 0], None, H, [0.0, 0.0], contact_dim=2)
    with pytest.raises(InputError, match="contact_dim"):
        LinearSystem(M, [0, 0], [0, 0], None, H, contact_dim=2.0)
    ball = bouncing_ball()
    with pytest.raises(InputError, match="chain"):
        LinearSystem(ball.M, ball.q0, ball.v0, None, np.ones((1, 2)), chain=ball.chain,
                     contact_dim=2)
    system = LinearSystem(M, [0, 1], [0, 0], [0, -1], H, contact_dim=2)
    assert system.n_contacts == 1 and np.allclose(system.gaps(system.q0), [0.0])
    assert system.contact_velocities([3.0, -2.0]).tolist() == [3.0]


def test_laws_and_systems_that_do_not_fit_are_refused_by_name():
    rough, smooth = block_on_incline(0.3), bouncing_ball()
    with pytest.raises(InputError, match="needs tangent columns"):
        simulate(smooth, Coulomb(0.3), 1.0)
    with pytest.raises(InputError, match="needs tangent columns"):
        moreau_jean(smooth, Coulomb(0.3), 1.0, 0.01)
    with pytest.raises(InputError, match="iq.Coulomb"):
        simulate(rough, Newton(0.5), 1.0)
    with pytest.raises(InputError, match="event-driven.*no Coulomb"):
        simulate(rough, Coulomb(0.3), 1.0, scheme="event-driven")
    with pytest.raises(InputError, match="event-driven.*no Coulomb"):
        simulate(rough, Newton(0.3), 1.0, scheme="event-driven")
    with pytest.raises(InputError, match="event-driven.*no Coulomb"):
        event_driven(rough, Coulomb(0.3), 1.0)
    with pytest.raises(InputError, match="compiled frictional loop does not take"):
        moreau_jean(rough, Coulomb(0.3), 1.0, 0.01, backend="nsgs", compiled=True)
    with pytest.raises(InputError, match="compiled frictional loop does not take"):
        moreau_jean(_spring_block(True), Coulomb(0.3), 1.0, 0.01, compiled=True)
    with pytest.raises(InputError, match="solve_friction"):
        simulate(rough, Coulomb(0.3), 1.0, backend="osqp")
    with pytest.raises(ShapeError, match="one per contact"):
        simulate(box_on_floor(2), Coulomb([0.1, 0.2, 0.3]), 1.0)


def test_per_contact_coefficients_act_on_their_own_contacts():
    """A box on two corners: μ given per corner acts on that corner only."""
    base = box_on_floor(2, velocity=2.0, gap=OVERLAP)
    tr_same = simulate(base, Coulomb([0.3, 0.3]), 0.2, h=0.01)
    tr_vec = simulate(base, Coulomb(0.3), 0.2, h=0.01)
    assert np.allclose(tr_same.v, tr_vec.v, atol=1e-9)
    tr_half = simulate(base, Coulomb([0.3, 0.0]), 0.2, h=0.01)
    assert tr_half.v[-1, 0] > tr_vec.v[-1, 0] + 0.1


def test_an_uncertified_step_stops_the_run_with_its_time(monkeypatch, loop):
    def fail(problem, **kwargs):
        raise CertificateError("no method certified the frictional contact problem")

    def kernel_fails(q, v, k, stop, row, *args):
        return FAILED, k, row  # the kernel's verdict on a step it does not certify

    monkeypatch.setattr(friction_step, "solve_friction", fail)
    monkeypatch.setattr(friction_loop, "run", kernel_fails)
    with pytest.raises(CertificateError, match=r"step ending at t = 0\.01 .*no method"):
        run(block_on_incline(0.3, gap=OVERLAP), Coulomb(0.3), 1.0, loop, h=0.01)


def test_the_compiled_loop_hands_a_step_it_cannot_certify_to_solve_friction(monkeypatch):
    """A step the kernel fails is solved by the Python step and the kernel resumes after it;
    the event buffers grow as they fill; both loops give the same run."""
    system = box_on_floor(3, velocity=(2.0, 1.0), gap=0.02)
    python = run(system, Coulomb(0.4, 0.3), 0.5, "friction", h=1e-3)
    kernel = friction_loop.run
    when = python.events[150].time  # a step with a local problem to solve
    fail = round(when / 1e-3) - 1

    def fail_once(q, v, k, stop, row, *args):
        if k <= fail < stop:  # stop before that step, then fail it
            status, k, row = kernel(q, v, k, fail, row, *args)
            return (FAILED if status == DONE else status), k, row
        return kernel(q, v, k, stop, row, *args)

    monkeypatch.setattr(friction_loop, "run", fail_once)
    mixed = run(system, Coulomb(0.4, 0.3), 0.5, "friction-compiled", h=1e-3)
    assert len(mixed.events) == len(python.events) > 300  # past the first buffers
    assert np.abs(mixed.v - python.v).max() < 1e-8 and np.abs(mixed.q - python.q).max() < 1e-8
    backends = [ev.result.backend for ev in mixed.events]
    by_python = [i for i, b in enumerate(backends) if b != friction_loop.LOOP_BACKEND]
    assert len(by_python) == 1 and mixed.events[by_python[0]].time == when
    for a, b in zip(mixed.events, python.events):
        assert a.time == b.time and np.array_equal(a.contacts, b.contacts) and a.certified
        assert np.allclose(a.u_plus, b.u_plus, atol=1e-8)


def test_a_frictional_trajectory_saves_its_impulse_components(tmp_path):
    tr = simulate(box_on_floor(2, velocity=1.0, gap=OVERLAP), Coulomb(0.3), 0.05, h=0.01)
    header = tr.save(tmp_path / "box.csv").read_text(encoding="utf-8").splitlines()[0]
    assert "lambda0_n,lambda0_t1,lambda1_n,lambda1_t1,kinetic_energy" in header
    events = (tmp_path / "box.events.csv").read_text(encoding="utf-8").splitlines()
    assert len(events) == 1 + len(tr.events) and ",coulomb,True," in events[1]
    with np.load(tr.save(tmp_path / "box.npz")) as data:
        assert np.array_equal(data["impulses"], tr.impulses)
        assert data["event_certified"].all() and data["event_admissible"].all()


def test_records_and_events_can_be_thinned(loop):
    system = box_on_floor(2, velocity=2.0, gap=0.01)
    full = run(system, Coulomb(0.3, 0.5), 0.3, loop, h=1e-3)
    thin = run(system, Coulomb(0.3, 0.5), 0.3, loop, h=1e-3, record_every=7, keep_events=False)
    rows = np.append(np.arange(0, 301, 7), 300)
    assert np.array_equal(thin.t, full.t[rows]) and thin.events == []
    assert np.array_equal(thin.q, full.q[rows]) and np.array_equal(thin.impulses,
                                                                    full.impulses[rows])


# --- units: the same motion whatever the unit of mass ------------------------------------------
@pytest.mark.parametrize("mass", [1e-12, 1e12])
def test_the_motion_does_not_depend_on_the_unit_of_mass(mass, loop):
    # each step's local problem is posed in its contacts' own units (docs/theory.md §17): in
    # raw units, with impulses 1e12 times the velocities, r − ũ rounded to r and a step whose
    # normal velocity was still 5e-5 of ‖q‖ into the floor passed the natural-map check
    reference = run(rolling_sphere(velocity=1.0, gap=OVERLAP), Coulomb(0.3), 0.5, loop,
                    h=1e-2)
    heavy = run(rolling_sphere(mass=mass, velocity=1.0, gap=OVERLAP), Coulomb(0.3), 0.5, loop,
                h=1e-2)
    assert np.abs(heavy.v - reference.v).max() < 1e-9
    assert np.allclose(heavy.impulses, mass * reference.impulses, rtol=1e-9,
                       atol=1e-9 * mass * np.abs(reference.impulses).max())
    assert all(ev.certified for ev in heavy.events)
    box = run(box_on_floor(3, mass=mass, velocity=(2.0, 1.5), gap=OVERLAP), Coulomb(0.4), 0.3,
              loop, h=1e-2)
    light = run(box_on_floor(3, velocity=(2.0, 1.5), gap=OVERLAP), Coulomb(0.4), 0.3, loop,
                h=1e-2)
    assert np.abs(box.v - light.v).max() < 1e-7  # rank-deficient W: to the tolerance


def test_the_laws_own_method_solves_the_steps():
    # Coulomb(method=...) is the method of every step unless simulate names a backend
    system = rolling_sphere(velocity=1.0, gap=OVERLAP)
    tr = simulate(system, Coulomb(0.3, method="clarabel"), 0.05, h=1e-2)
    assert tr.settings["loop"] == "friction"
    assert all(ev.result.backend.startswith("clarabel") for ev in tr.events)
    tr = simulate(system, Coulomb(0.3, method="clarabel"), 0.05, h=1e-2, backend="nsgs")
    assert all(ev.result.backend.startswith("nsgs") for ev in tr.events)
    assert simulate(system, Coulomb(0.3), 0.05, h=1e-2).settings["loop"] == "friction-compiled"
