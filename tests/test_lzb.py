"""The LZB model of dispersive multiple impacts (docs/theory.md §13): Siconos' chain of balls,
the three-ball chain in closed form and against a time integration of the compliant chain,
convergence, dissipation, certificates, physical chains and the comparison with the rigid
laws."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import impactqp as iq
from impactqp.laws.lzb import LZB, LZBCertificate
from impactqp.model.physical_chains import (
    ball_chain,
    hertz_stiffness,
    monodisperse_chain,
    sphere_mass,
    tapered_chain,
)
from impactqp.verification.compare import compare_chain, compare_laws

# Post-impact velocities of Siconos' ChainOfBalls example (LZB model, 10 steel balls of
# radius 0.01 m, density 7780 kg/m³, E = 203 GPa, ν = 0.3, Hertz exponent 1.5, e = 1,
# striker at 1 m/s onto 9 touching balls at rest): the row just after the impact at t = 0.2
# s, columns 12–21, of examples/mechanics/ChainOfBalls/MonodisperseChainOfBalls-LZBModel.ref
# in github.com/siconos/siconos-tutorials, commit b6c9bfd1940a69dae512a3e39cf5f1a951e3eebe
# (file last changed in 16735ddf79713b794171c8f4b56693323ba3e2f0). Siconos is Apache-2.0.
# Siconos integrates with fixed impulse steps of 1e-6 N·s; its momentum is exact but its
# energy is off by 2.6e-5 relative, so agreement to 1e-3 m/s is what it supports.
SICONOS_CHAIN_OF_BALLS = np.array([
    -7.105929287758861e-02, -3.018624045788600e-02, -1.574960308766378e-02,
    -8.808055289868551e-03, -5.062343781337067e-03, -2.936631945849190e-03,
    -1.701856524055756e-03, 2.624517363818925e-03, 1.469233855937676e-01,
    9.859561210066624e-01])


def momentum_error(p: iq.ImpactProblem, u_plus: np.ndarray) -> float:
    m = p.chain.masses
    return abs(m @ u_plus - m @ p.u_minus) / (m @ np.abs(p.u_minus))


def energy_error(p: iq.ImpactProblem, u_plus: np.ndarray) -> float:
    return abs(p.kinetic_energy(u_plus) - p.kinetic_energy()) / p.kinetic_energy()


def hertz_chain_in_time(masses: np.ndarray, stiffness: float, exponent: float,
                        u_minus: np.ndarray) -> np.ndarray:
    """Final velocities of the compliant chain m ẍ = forces, Fᵢ = K max(xᵢ − xᵢ₊₁, 0)^η,
    integrated in time: the same model as LZB with e = 1, by a route without impulses."""
    n = masses.size

    def rates(t, s):
        x, v = s[:n], s[n:]
        force = stiffness * np.maximum(x[:-1] - x[1:], 0.0) ** exponent
        a = np.zeros(n)
        a[:-1] -= force
        a[1:] += force
        return np.concatenate([v, a / masses])

    def apart(t, s):  # every contact open and separating: the impact is over
        x, v = s[:n], s[n:]
        return 1.0 if np.all(x[:-1] - x[1:] < 0) and np.all(np.diff(v) >= 0) else -1.0

    apart.terminal = True
    span = 50.0 * (masses.max() / stiffness) ** (1 / (exponent + 1)) * n
    sol = solve_ivp(rates, (0.0, span), np.concatenate([np.zeros(n), u_minus]),
                    method="DOP853", rtol=1e-12, atol=1e-14, events=apart)
    return sol.y[n:, -1]


# --------------------------------------------------------------------------- Siconos
def test_ten_ball_chain_matches_siconos_and_conserves() -> None:
    chain = monodisperse_chain(10, 0.01, density=7780, young=203e9, poisson=0.3)
    r = iq.solve(chain.problem, LZB(chain.stiffness, exponent=1.5, restitution=1.0))
    assert r.backend == "lzb" and isinstance(r.certificate, LZBCertificate)
    assert np.abs(r.u_plus - SICONOS_CHAIN_OF_BALLS).max() <= 1e-3
    assert momentum_error(chain.problem, r.u_plus) <= 1e-12
    assert energy_error(chain.problem, r.u_plus) <= 1e-6
    record = r.certificate.record
    assert record.primary_switches >= 8  # the primary contact runs down the chain
    assert record.potential_energy.sum() <= 1e-12 * chain.problem.kinetic_energy()
    assert np.all(record.impulses >= 0) and np.all(record.dissipated == 0)
    assert np.all(np.diff(r.u_plus) >= 0)  # every contact separates: no later impact
    assert r.admissible  # an elastic LZB outcome lies in S
    # the same compliant chain integrated in time, without the impulse parametrization
    reference = hertz_chain_in_time(chain.masses, float(chain.stiffness[0]), 1.5,
                                    chain.problem.u_minus)
    assert np.abs(r.u_plus - reference).max() <= 1e-7


def test_siconos_fixed_steps() -> None:
    """Siconos' own step, 1e-6 N·s in the primary impulse (about 2·10⁵ steps), runs to the
    same answer, and a coarser one certifies at the accuracy its steps reach."""
    chain = monodisperse_chain(10, 0.01, density=7780, young=203e9, poisson=0.3)
    adaptive = iq.solve(chain.problem, LZB(chain.stiffness)).u_plus
    for step in (1e-6, 1e-4):
        r = iq.solve(chain.problem, LZB(chain.stiffness, step=step))
        assert r.certificate.ok and r.certificate.record.method == f"fixed step {step:g}"
        assert np.abs(r.u_plus - adaptive).max() <= 1e-8
        assert np.abs(r.u_plus - SICONOS_CHAIN_OF_BALLS).max() <= 1e-3
    assert r.certificate.record.steps < 5_000


# --------------------------------------------------------------------------- 3 balls
def linear_three_balls() -> np.ndarray:
    """Three equal balls m = 1, linear springs k = 1, u⁻ = (1, 0, 0), in closed form
    (docs/theory.md §13): both springs loaded until δ₁ returns to 0, then balls 2 and 3 alone."""
    s3 = np.sqrt(3.0)

    def delta1(t: float) -> float:
        return 0.5 * np.sin(t) + np.sin(s3 * t) / (2 * s3)

    t1 = brentq(delta1, 2.0, 3.0)
    delta2 = 0.5 * np.sin(t1) - np.sin(s3 * t1) / (2 * s3)
    rate1 = 0.5 * np.cos(t1) + 0.5 * np.cos(s3 * t1)  # u₁ − u₂
    rate2 = 0.5 * np.cos(t1) - 0.5 * np.cos(s3 * t1)  # u₂ − u₃
    u = np.linalg.solve([[1.0, -1.0, 0.0], [0.0, 1.0, -1.0], [1.0, 1.0, 1.0]],
                        [rate1, rate2, 1.0])
    centre, final = 0.5 * (u[1] + u[2]), -np.sqrt(rate2**2 + 2.0 * delta2**2)
    return np.array([u[0], centre + 0.5 * final, centre - 0.5 * final])


def test_three_balls_linear_compliance_closed_form() -> None:
    p = iq.newtons_cradle(3)
    expected = linear_three_balls()
    assert np.allclose(expected, [-0.13026, 0.15023, 0.98003], atol=1e-5)
    for k in (1.0, 1e7):  # a linear chain's outcome does not depend on the stiffness
        r = iq.solve(p, LZB(k, exponent=1.0))
        assert np.abs(r.u_plus - expected).max() <= 1e-8
        assert r.admissible and r.certificate.ok


def test_three_balls_hertz() -> None:
    p = iq.newtons_cradle(3)
    r = iq.solve(p, LZB(1e6))
    u = r.u_plus
    # the striker rebounds, the middle ball keeps a little, the last carries nearly all
    assert u[0] < 0 < u[1] < 0.1 < 0.99 < u[2] < 1
    assert np.abs(u - [-0.070952, 0.076403, 0.994549]).max() <= 1e-6
    assert np.abs(u - hertz_chain_in_time(np.ones(3), 1e6, 1.5, p.u_minus)).max() <= 1e-8
    assert r.admissible
    assert r.certificate.record.primary_switches == 1
    # homogeneous: u⁺ scales with u⁻ and does not depend on a common stiffness
    assert np.allclose(iq.solve(p.with_u_minus(3 * p.u_minus), LZB(5e4)).u_plus, 3 * u,
                       atol=1e-8)


# --------------------------------------------------------------------------- convergence
def test_adaptive_tolerance_converges() -> None:
    chain = monodisperse_chain(10)
    u = [LZB(chain.stiffness, rtol=rtol, energy_target=None).integrate(chain.problem).u_plus
         for rtol in (1e-6, 1e-8, 1e-10, 1e-12)]
    changes = [np.abs(b - a).max() for a, b in zip(u, u[1:])]
    assert changes[0] > changes[1] > changes[2]
    assert changes[2] <= 1e-7


def test_fixed_step_converges() -> None:
    p = iq.newtons_cradle(3)
    for e in (1.0, 0.5):
        u = [LZB(1e6, restitution=e, step=h).integrate(p).u_plus for h in (8e-3, 4e-3, 2e-3)]
        changes = [np.abs(b - a).max() for a, b in zip(u, u[1:])]
        assert changes[0] > changes[1], (e, changes)
        adaptive = LZB(1e6, restitution=e).integrate(p).u_plus
        assert np.abs(u[-1] - adaptive).max() <= 1e-6


# --------------------------------------------------------------------------- dissipation
def test_two_balls_restitution_is_newtons() -> None:
    p = iq.newtons_cradle(2)
    for e in (0.0, 0.3, 0.8, 1.0):
        r = iq.solve(p, LZB(2e5, restitution=e))
        assert np.allclose(r.u_plus, [(1 - e) / 2, (1 + e) / 2], atol=1e-9)
        lost = r.certificate.record.dissipated.sum()
        assert lost == pytest.approx(r.energy_before - r.energy_after, abs=1e-9)


def test_dissipative_chain_energy_balance_and_S() -> None:
    chain = tapered_chain(5)
    r = iq.solve(chain.problem, LZB(chain.stiffness, restitution=[0.9, 0.5, 0.7, 0.2]))
    rec = r.certificate.record
    assert r.certificate.ok and r.certificate.energy_balance <= 1e-9
    balance = r.energy_after + rec.dissipated.sum() + rec.potential_energy.sum()
    assert balance == pytest.approx(r.energy_before, rel=1e-9)
    assert np.all(rec.dissipated > 0) and r.energy_after < r.energy_before
    assert r.admissible


def test_plastic_three_balls_end_together() -> None:
    r = iq.solve(iq.newtons_cradle(3), LZB(1e6, restitution=0.0))
    assert np.allclose(r.u_plus, 1 / 3, atol=1e-9)  # as Moreau's law at ε = 0
    assert r.admissible


def test_general_impacts_and_batches() -> None:
    for p in (iq.random_impact(6, 4, seed=1), iq.chain([1.0, 1.0, 1.0], [0, 0, -1.0],
                                                        left_wall=True)):
        r = iq.solve(p, LZB(1e5))
        assert r.certificate.ok and r.admissible
    p = iq.newtons_cradle(3)
    U = np.array([[1.0, 0, 0], [1, 0, -1], [0, 0, 0], [-1, 0, 1], [1, 1, 0]])
    batch = iq.solve_batch(p, LZB(1e6), U)
    assert batch.ok.all() and batch.backend == "lzb"
    assert np.allclose(batch.u_plus[0], iq.solve(p, LZB(1e6)).u_plus)
    assert np.allclose(batch.u_plus[1], [-1, 0, 1], atol=1e-9)  # a symmetric head-on impact
    assert np.array_equal(batch.u_plus[2:4], U[2:4])  # nothing approaches: no impact


def test_failed_certificate_is_never_returned() -> None:
    p = iq.newtons_cradle(3)

    class Tampered(LZB):  # an integration whose answer loses energy it does not record
        def closed_form(self, problem: iq.ImpactProblem) -> iq.chains.LZBAnswer:
            answer = self.integrate(problem)
            return answer._replace(u_plus=answer.u_plus * (1 - 1e-6),
                                   impulses=answer.impulses * (1 - 1e-6))

    with pytest.raises(iq.CertificateError, match="LZB"):
        iq.solve(p, Tampered(1e6))
    # coarse fixed steps: the integration's own error estimate sets the tolerance of the
    # residuals it decides; with the estimate erased the same answer fails at tol = 1e-12
    law = LZB(1e6, step=0.02)
    r = iq.solve(p, law, tol=1e-12)
    cert = r.certificate
    assert cert.ok and cert.tol == 1e-12 and 1e-12 < cert.integration_tol <= 1e-5
    assert 1e-12 < cert.energy_balance <= cert.integration_tol
    erased = dataclasses.replace(cert.record, error_estimate=0.0)
    answer = iq.chains.LZBAnswer(r.u_plus, r.impulses, None, erased)
    assert not law.certificate(p, answer, tol=1e-12).ok


def test_restrict_to_contacts() -> None:
    law = LZB([1.0, 2.0, 3.0], exponent=1.0, restitution=[1.0, 0.5, 0.2])
    sub = law.restrict([0, 2])
    assert np.array_equal(sub.stiffness, [1.0, 3.0])
    assert np.array_equal(sub.restitution, [1.0, 0.2]) and sub.exponent == 1.0


# --------------------------------------------------------------------------- input
def test_bad_input_names_the_argument() -> None:
    with pytest.raises(iq.InputError, match="stiffness"):
        LZB(-1.0)
    with pytest.raises(iq.InputError, match="exponent"):
        LZB(1.0, exponent=0.0)
    with pytest.raises(iq.errors.RestitutionError, match="restitution"):
        LZB(1.0, restitution=1.5)
    with pytest.raises(iq.InputError, match="step"):
        LZB(1.0, step=-1e-3)
    with pytest.raises(iq.InputError, match="rtol"):
        LZB(1.0, rtol=0.5)
    with pytest.raises(iq.errors.ShapeError, match="stiffness"):
        iq.solve(iq.newtons_cradle(3), LZB([1.0, 2.0, 3.0]))
    with pytest.raises(iq.InputError, match="two walls"):
        iq.solve(iq.chain([1.0, 1.0], [1.0, -1.0], left_wall=True, right_wall=True), LZB(1.0))
    with pytest.raises(iq.BackendUnsuitableError):
        iq.solve(iq.newtons_cradle(3), LZB(1.0), backend="clarabel")


# --------------------------------------------------------------------------- chains
def test_physical_chains() -> None:
    # Siconos' stiffness of two equal steel spheres: (2/3)E/(1 − ν²)·√(R/2)
    k = hertz_stiffness(0.01, 0.01, 203e9, 0.3)
    assert k == pytest.approx(2 / 3 * 203e9 / (1 - 0.09) * np.sqrt(0.005), rel=1e-14)
    assert sphere_mass(0.01, 7780) == pytest.approx(4 / 3 * np.pi * 1e-6 * 7780, rel=1e-14)
    chain = tapered_chain(4, radius=0.02, taper=0.1)
    assert np.allclose(chain.radii, 0.02 * 0.9 ** np.arange(4))
    assert np.allclose(chain.stiffness, hertz_stiffness(chain.radii[:-1], chain.radii[1:]))
    assert np.array_equal(chain.problem.u_minus, [1.0, 0, 0, 0])
    mixed = ball_chain([0.01, 0.01], young=[203e9, 70e9], poisson=[0.3, 0.33])
    assert mixed.stiffness[0] < k
    with pytest.raises(iq.InputError, match="radius"):
        monodisperse_chain(3, radius=-0.01)
    with pytest.raises(iq.InputError, match="taper"):
        tapered_chain(3, taper=1.0)
    with pytest.raises(iq.InputError, match="poisson"):
        ball_chain([0.01, 0.01], poisson=0.7)
    with pytest.raises(iq.errors.ShapeError, match="radii"):
        ball_chain([0.01])


# --------------------------------------------------------------------------- comparison
def test_comparison_table_and_S() -> None:
    c = compare_chain(monodisperse_chain(3))
    assert [o.law for o in c.outcomes] == ["Moreau ε = 0", "Moreau ε = 1", "sector law", "LZB"]
    assert all(o.in_S for o in c.outcomes)
    assert np.allclose(c["sector law"].u_plus, [0, 0, 1])
    assert c.lzb.energy_ratio == pytest.approx(1.0, abs=1e-9)
    table = c.table()
    assert table.count("\n") == 5 and "| LZB | -0.0710 | 0.0764 | 0.9945 | 1.0000 | yes |" in table
    tapered = compare_chain(tapered_chain(5))
    assert tapered["sector law"].result is None and "unequal masses" in tapered["sector law"].note
    assert tapered.lzb.in_S and "–" in tapered.table()
    with pytest.raises(iq.InputError):
        compare_laws(iq.newtons_cradle(3), iq.Moreau(0.5))


def test_comparison_figure(tmp_path) -> None:
    pytest.importorskip("matplotlib")
    from impactqp.figures.compare_plot import plot_comparison

    out = plot_comparison([compare_chain(monodisperse_chain(3)),
                           compare_chain(tapered_chain(4))], tmp_path / "c.png",
                          titles=["3 balls", "tapered"])
    assert out.stat().st_size > 10_000
    with pytest.raises(iq.InputError, match="titles"):
        plot_comparison([compare_chain(monodisperse_chain(3))], tmp_path / "d.png",
                        titles=["a", "b"])
