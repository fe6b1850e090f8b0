"""Derivatives of impact maps (docs/theory.md §18–§20): Jacobians and JVPs against central
finite differences of iq.solve on random families, VJP/JVP consistency, the three-ball
kink, the ε identity, the sector law's ties, unsupported laws and bad input."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.derivatives.certificate import random_direction
from impactqp.errors import DerivativeUnsupportedError, InputError, ShapeError
from impactqp.results import LinearPiece


def family(seed: int) -> tuple[iq.ImpactProblem, iq.ImpactLaw]:
    """A random dense impact: n ≤ 30, masses over 1e-3…1e3, and a law of the family."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 31))
    m = int(rng.integers(1, min(n, 12) + 1))
    masses = 10.0 ** rng.uniform(-3, 3, n)
    B = rng.normal(size=(n, n)) / np.sqrt(n)
    S = np.diag(np.sqrt(masses))
    M = S @ (np.eye(n) + 0.3 * B @ B.T) @ S
    W = rng.normal(size=(n, m))
    u = rng.normal(size=n) / np.sqrt(masses)
    kind = seed % 4
    law = [iq.Moreau(float(rng.uniform(0, 1))), iq.Newton(float(rng.uniform(0, 1))),
           iq.Newton(rng.uniform(0, 1, m)),
           iq.Fremond(np.diag(rng.uniform(0, 1, m)) + 0.05 * rng.uniform(0, 1, (m, m)))][kind]
    return iq.ImpactProblem(0.5 * (M + M.T), W, u), law


def solve_at(problem, law, u=None, M=None, W=None):
    p = iq.ImpactProblem(problem.M if M is None else M, problem.W if W is None else W,
                         problem.u_minus if u is None else u)
    return iq.solve(p, law)


def relative(a: np.ndarray, b: np.ndarray, scale: float) -> float:
    return float(np.linalg.norm(a - b) / max(np.linalg.norm(b), scale))


@pytest.mark.parametrize("seed", range(16))
def test_random_families_agree_with_central_differences(seed: int) -> None:
    problem, law = family(seed)
    r = iq.solve(problem, law)
    d = r.derivative()
    assert d.certificate.ok
    # the seeds are fixed: each point lies inside a cell, so a kink here is a misclassification
    assert d.status == "smooth"
    u = problem.u_minus
    unorm = float(np.linalg.norm(u))
    rng = np.random.default_rng(1000 + seed)
    # u⁻: the map is affine on the cell, so a step of a quarter of the margin is exact
    du = rng.normal(size=u.size)
    du *= unorm / np.linalg.norm(du)
    h = 0.25 * min(d.certificate.margin, 1.0)
    fd = (solve_at(problem, law, u=u + h * du).u_plus
          - solve_at(problem, law, u=u - h * du).u_plus) / (2 * h)
    assert relative(d.jvp(u_minus=du).u_plus, fd, unorm) <= 1e-7
    J = d.jacobian("u_minus")
    assert np.allclose(J @ du, d.jvp(u_minus=du).u_plus, rtol=1e-12, atol=1e-12 * unorm)
    # M (symmetric) and W: smooth, central differences of second order
    dM = random_direction(rng, "M", problem.M)
    dW = random_direction(rng, "W", problem.W)
    h = 1e-6
    for name, step in (("M", dM), ("W", dW)):
        plus = solve_at(problem, law, **{name: getattr(problem, name) + h * step}).u_plus
        minus = solve_at(problem, law, **{name: getattr(problem, name) - h * step}).u_plus
        fd = (plus - minus) / (2 * h)
        assert relative(d.jvp(**{name: step}).u_plus, fd, unorm) <= 1e-5, name
    audit = d.certificate.audit(3)
    assert audit.ok and not audit.one_sided


@pytest.mark.parametrize("seed", range(8))
def test_vjp_is_the_transpose_of_jvp(seed: int) -> None:
    problem, law = family(seed)
    d = iq.derivative(problem, law)
    rng = np.random.default_rng(seed)
    name = next(k for k in d.inputs if k not in ("u_minus", "M", "W"))
    t = {k: rng.normal(size=shape) for k, shape in d.inputs.items()}
    ub, lb = rng.normal(size=problem.n_dof), rng.normal(size=problem.n_impulses)
    tan = d.jvp(**t)
    cot = d.vjp(u_plus=ub, impulses=lb)
    lhs = ub @ tan.u_plus + lb @ tan.impulses
    rhs = sum(float(np.sum(cot[k] * t[k])) for k in t)
    assert abs(lhs - rhs) <= 1e-10 * (abs(lhs) + sum(np.abs(cot[k]).sum() *
                                                      np.abs(t[k]).max() for k in t))
    assert name in ("eps", "e", "E")
    # the dense Jacobians are the VJPs of the unit rows
    assert d.jacobian(name).shape == (problem.n_dof, *d.inputs[name])
    assert np.allclose(d.jacobian("W", of="impulses")[0], d.vjp(
        impulses=np.eye(problem.n_impulses)[0])["W"])


def test_moreau_jacobian_is_I_minus_projection() -> None:
    problem = iq.random_impact(7, 4, seed=5)
    r = iq.solve(problem, iq.Moreau(0.6))
    d = r.derivative()
    A = r.impulses > 0
    M, W = problem.M, problem.W[:, A]
    P = np.linalg.solve(M, W) @ np.linalg.solve(W.T @ np.linalg.solve(M, W), W.T)
    assert np.allclose(d.jacobian(), np.eye(7) - 1.6 * P, atol=1e-12)
    # M-self-adjoint: (MJ)ᵀ = MJ
    MJ = M @ d.jacobian()
    assert np.allclose(MJ, MJ.T, atol=1e-12)
    assert np.allclose(d.jacobian("eps"), r.z - problem.u_minus, atol=1e-12)


def three_balls():
    return iq.solve(iq.newtons_cradle(3).with_u_minus([1.0, 0.0, 0.5]), iq.Moreau(0.0))


def test_the_three_ball_kink() -> None:
    r = three_balls()
    assert np.allclose(r.u_plus, 0.5)
    d = r.derivative()
    assert d.status == "kink" and d.kink.contacts.tolist() == [1]
    assert d.certificate.margin == 0.0 and d.certificate.ok
    e3 = np.array([0.0, 0.0, 1.0])
    assert np.allclose(d.directional(u_minus=e3).u_plus, [0, 0, 1], atol=1e-14)
    assert np.allclose(d.directional(u_minus=-e3).u_plus, [-1 / 3] * 3, atol=1e-14)
    # both sides by one-sided differences of the solve
    for sign, expected in ((1, [0, 0, 1]), (-1, [-1 / 3] * 3)):
        h = 1e-6
        fd = (iq.moreau(iq.newtons_cradle(3).with_u_minus([1, 0, 0.5 + sign * h]), 0.0).u_plus
              - r.u_plus) / h
        assert np.allclose(fd, expected, atol=1e-8)
    J = d.limiting_jacobians()
    assert len(J) == 2
    assert np.allclose(J[0], [[0.5, 0.5, 0], [0.5, 0.5, 0], [0, 0, 1]])
    assert np.allclose(J[1], np.full((3, 3), 1 / 3))
    assert np.allclose(d.jacobian(), J[0])  # the documented default element (S = ∅)
    assert len(d.limiting_jacobians(cap=1)) == 1
    assert d.certificate.audit(4).ok and d.certificate.audit(4).one_sided


@pytest.mark.parametrize("eps", [0.0, 0.3, 1.0])
def test_eps_identity_holds_at_kinks(eps: float) -> None:
    p = iq.newtons_cradle(3).with_u_minus([1.0, 0.0, 0.5])  # contact 2 degenerate for every ε
    r = iq.solve(p, iq.Moreau(eps))
    d = r.derivative()
    assert d.status == "kink"
    z = r.z
    for sign in (1.0, -1.0):
        assert np.allclose(sign * (z - p.u_minus), d.directional(eps=sign).u_plus, atol=1e-12)
    assert np.allclose(d.jacobian("eps"), z - p.u_minus, atol=1e-12)
    h = 1e-4
    lo, hi = max(eps - h, 0.0), min(eps + h, 1.0)
    fd = (iq.moreau(p, hi).u_plus - iq.moreau(p, lo).u_plus) / (hi - lo)
    assert np.allclose(fd, z - p.u_minus, atol=1e-9)


def test_sector_law_ties_sort_the_direction() -> None:
    p = iq.newtons_cradle(4).with_u_minus([1.0, 0.5, 0.5, -1.0])
    r = iq.sector_law(p)
    d = r.derivative()
    assert d.status == "kink" and d.kink.contacts.tolist() == [1, 2]
    assert list(d.inputs) == ["u_minus"]
    for du in ([0, 1.0, 0, 0], [0, -1.0, 0, 0], [0.3, 1.0, -2.0, 0.1]):
        du = np.array(du)
        h = 1e-7
        fd = (iq.sector_law(p.with_u_minus(p.u_minus + h * du)).u_plus - r.u_plus) / h
        got = d.directional(u_minus=du)
        assert np.allclose(got.u_plus, fd, atol=1e-7)
        fdl = (iq.sector_law(p.with_u_minus(p.u_minus + h * du)).impulses - r.impulses) / h
        assert np.allclose(got.impulses, fdl, atol=1e-6)
    Js = d.limiting_jacobians()
    assert len(Js) == 2 and all(np.allclose(J.sum(axis=0), 1) for J in Js)
    with pytest.raises(InputError, match="not 'M'"):
        d.jacobian("M")


def test_sector_law_smooth_jacobian_and_vjp() -> None:
    p = iq.newtons_cradle(5).with_u_minus([3.0, -1.0, 2.0, 0.5, -2.0])
    d = iq.sector_law(p).derivative()
    assert d.status == "smooth"
    J = d.jacobian()
    assert np.allclose(J @ p.u_minus, np.sort(p.u_minus))
    JL = d.jacobian(of="impulses")
    ub, lb = np.arange(5.0), np.arange(4.0) - 1
    assert np.allclose(d.vjp(u_plus=ub, impulses=lb)["u_minus"], J.T @ ub + JL.T @ lb)
    assert d.certificate.audit(3).ok


def test_laws_without_a_derivative_say_so_by_name() -> None:
    class Stop(iq.ImpactLaw):
        """u⁺ = (I − WWᵀ/2)u⁻ on one contact (a user's law without a derivative hook)."""

        def closed_form(self, problem):
            return problem.u_minus - problem.W[:, 0] * (problem.gamma_minus[0] / 2)

    p = iq.ImpactProblem(np.eye(2), np.array([[1.0], [-1.0]]), [-1.0, 1.0])
    d = iq.solve(p, Stop()).derivative()
    assert d.status == "unsupported" and "Stop" in d.reason
    assert not d.certificate.ok
    with pytest.raises(DerivativeUnsupportedError, match="Stop"):
        d.jacobian()
    with pytest.raises(DerivativeUnsupportedError):
        d.certificate.audit()
    d = iq.solve(iq.newtons_cradle(3), iq.LZB(1e6)).derivative()
    assert d.status == "unsupported" and "LZB" in d.reason


def test_a_users_hook_gives_a_linear_piece() -> None:
    class Stop(iq.ImpactLaw):
        """u⁺ = (I − WWᵀ/2)u⁻ on one contact, with its derivative."""

        def closed_form(self, problem):
            return problem.u_minus - problem.W[:, 0] * (problem.gamma_minus[0] / 2)

        def derivative(self, problem, answer, *, kink_tol):
            J = np.eye(problem.n_dof) - np.outer(problem.W[:, 0], problem.W[:, 0]) / 2
            return LinearPiece({"u_minus": J}, {"u_minus": problem.u_minus})

    p = iq.ImpactProblem(np.eye(2), np.array([[1.0], [-1.0]]), [-1.0, 1.0])
    d = iq.solve(p, Stop()).derivative()
    assert d.status == "smooth"
    J = np.array([[0.5, 0.5], [0.5, 0.5]])
    assert np.allclose(d.jacobian(), J)
    assert np.allclose(d.vjp(u_plus=[1.0, 2.0])["u_minus"], J.T @ [1.0, 2.0])
    assert d.certificate.audit(2).ok


def test_bad_input_is_named() -> None:
    d = three_balls().derivative()
    with pytest.raises(InputError, match="not 'mass'"):
        d.jacobian("mass")
    with pytest.raises(InputError, match="of must be"):
        d.jacobian("u_minus", of="z")
    with pytest.raises(ShapeError, match="u_minus"):
        d.jvp(u_minus=[1.0, 2.0])
    with pytest.raises(ShapeError, match="u_plus"):
        d.vjp(u_plus=np.ones(4))
    with pytest.raises(InputError, match="not 'e'"):
        d.jvp(e=0.1)
    with pytest.raises(InputError, match="kink_tol"):
        three_balls().derivative(kink_tol=-1.0)
    long_chain = iq.chain(np.ones(2500), np.r_[1.0, np.zeros(2499)])
    with pytest.raises(DerivativeUnsupportedError, match="densely"):
        iq.moreau(long_chain, 0.0).derivative()


def test_redundant_contacts_give_minimum_norm_impulses() -> None:
    W = np.array([[1.0, 1.0], [-1.0, -1.0]])  # two copies of one contact
    p = iq.ImpactProblem(np.eye(2), W, [-1.0, 1.0])
    r = iq.moreau(p, 0.5)
    d = r.derivative()
    assert d.status == "smooth" and not d.impulses_unique
    dl = d.jvp(u_minus=[1.0, 0.0]).impulses
    assert np.isclose(dl[0], dl[1])  # the minimum-norm split
    h = 1e-6
    fd = (iq.moreau(p.with_u_minus([-1 + h, 1.0]), 0.5).u_plus - r.u_plus) / h
    assert np.allclose(d.jvp(u_minus=[1.0, 0.0]).u_plus, fd, atol=1e-8)


@pytest.mark.parametrize("law", [iq.Moreau(0.3), iq.Newton([0.2, 0.9, 0.5, 0.0]),
                                 iq.Fremond(0.2 * np.eye(4) + 0.05)])
def test_derivative_batch_equals_single_derivatives(law) -> None:
    p = iq.random_impact(6, 4, seed=8, consistent=False)
    rng = np.random.default_rng(3)
    U, dU, Ub = (rng.normal(size=(40, 6)) for _ in range(3))
    U[0] = p.u_minus
    b = iq.derivative_batch(p, law, U, jvp=dU, vjp=Ub)
    assert b.backend == "kernel"
    for i in range(40):
        d = iq.derivative(p.with_u_minus(U[i]), law)
        assert b.status[i] == d.status
        assert np.allclose(b.jvp[i], d.jvp(u_minus=dU[i]).u_plus, atol=1e-12)
        assert np.allclose(b.vjp[i], d.vjp(u_plus=Ub[i])["u_minus"], atol=1e-12)
        assert np.isclose(b.margin[i], d.certificate.margin, rtol=1e-9)


def test_derivative_batch_kinks_other_laws_and_errors() -> None:
    p = iq.newtons_cradle(3)
    U = np.array([[1.0, 0.0, 0.5], [1.0, 0.0, -1.0]])
    b = iq.derivative_batch(p, iq.Moreau(0.0), U, jvp=np.tile([0, 0, 1.0], (2, 1)))
    assert b.status.tolist() == ["kink", "smooth"] and b.margin[0] == 0.0
    assert np.allclose(b.jvp[0], [0, 0, 1])  # the default element, as jvp() gives it
    assert b.vjp is None
    s = iq.derivative_batch(p, iq.SectorLaw(), U, vjp=np.eye(3)[:2])
    assert s.backend == "rows" and s.status.tolist() == ["smooth", "smooth"]
    with pytest.raises(ShapeError, match="jvp"):
        iq.derivative_batch(p, iq.Moreau(0.0), U, jvp=np.ones((3, 3)))
    with pytest.raises(DerivativeUnsupportedError):
        iq.derivative_batch(p, iq.LZB(1e6), U)


def ball_on_floor(vx: float) -> iq.ImpactProblem:
    """A unit point mass hitting a floor (normal y, tangent x) at (vx, −1)."""
    return iq.ImpactProblem(np.eye(2), np.array([[0.0, 1.0], [1.0, 0.0]]), [vx, -1.0],
                            contact_dim=2)


def test_coulomb_stick_and_slide_with_mu_derivative() -> None:
    law = iq.Coulomb(0.5, 0.3)  # sticks for vx ≤ μ(1 + e) = 0.65
    stick = iq.solve(ball_on_floor(0.3), law).derivative()
    slide = iq.solve(ball_on_floor(0.9), law).derivative()
    assert stick.status == slide.status == "smooth"
    assert np.allclose(stick.jacobian("mu"), 0.0)  # exactly 0 while sticking
    assert np.allclose(stick.jacobian(), [[0, 0], [0, -0.3]])
    assert np.allclose(slide.jacobian(), [[1, 0.65], [0, -0.3]])
    assert np.allclose(slide.jacobian("mu"), [-1.3, 0.0])
    assert np.allclose(slide.jacobian("restitution"), [-0.5, 1.0])
    for d, vx in ((stick, 0.3), (slide, 0.9)):
        h = 1e-6
        fd = (iq.solve(ball_on_floor(vx), iq.Coulomb(0.5 + h, 0.3)).u_plus
              - iq.solve(ball_on_floor(vx), iq.Coulomb(0.5 - h, 0.3)).u_plus) / (2 * h)
        assert np.allclose(d.jacobian("mu"), fd, atol=1e-7)
        assert d.certificate.audit(4).ok
    assert np.isclose(stick.certificate.margin * np.hypot(0.3, 1.0),
                      0.35 / np.hypot(1.0, 0.65))  # the distance to the threshold


def test_coulomb_threshold_both_sides() -> None:
    r = iq.solve(ball_on_floor(0.65), iq.Coulomb(0.5, 0.3))
    d = r.derivative()
    assert d.status == "kink" and d.kink.contacts.tolist() == [0]
    ex = np.array([1.0, 0.0])
    assert np.allclose(d.directional(u_minus=ex).u_plus, [1, 0])  # starts to slide
    assert np.allclose(d.directional(u_minus=-ex).u_plus, [0, 0])  # keeps sticking
    for sign in (1.0, -1.0):
        h = 1e-7
        fd = (iq.solve(ball_on_floor(0.65 + sign * h), iq.Coulomb(0.5, 0.3)).u_plus
              - r.u_plus) / h
        assert np.allclose(fd, d.directional(u_minus=sign * ex).u_plus, atol=1e-6)
    # along μ: more friction keeps it sticking (0), less lets it slide
    assert np.allclose(d.directional(mu=1.0).u_plus, 0.0)
    assert np.allclose(d.directional(mu=-1.0).u_plus, [1.3, 0.0])
    J = d.limiting_jacobians()
    assert len(J) == 2 and np.allclose(J[0], [[0, 0], [0, -0.3]])
    assert np.allclose(J[1], [[1, 0.65], [0, -0.3]])


def test_coulomb_in_space_against_finite_differences() -> None:
    rng = np.random.default_rng(1)
    W = rng.normal(size=(6, 6))
    p = iq.ImpactProblem(2 * np.eye(6), W, rng.normal(size=6), contact_dim=3)
    d = iq.solve(p, iq.Coulomb([0.3, 0.8], 0.5)).derivative()
    assert d.status == "smooth" and d.certificate.ok
    audit = d.certificate.audit(6)
    assert audit.ok, audit.errors
    t = {k: rng.normal(size=s) for k, s in d.inputs.items()}
    tan, cot = d.jvp(**t), d.vjp(u_plus=np.ones(6))
    assert np.isclose(np.ones(6) @ tan.u_plus, sum(np.sum(cot[k] * t[k]) for k in t))


def test_the_agreement_benchmark_counts_every_problem_and_finds_no_false_smooth() -> None:
    """benchmarks/derivatives.py's random-family check (issue 26's first target) on a few
    problems: every problem is counted once and no smooth derivative misses the differences."""
    from benchmarks.derivatives import agreement

    a = agreement(12, seed=3)
    assert a["smooth"] + a["other"] == a["problems"] == 12
    assert a["agree"] + a["disagree"] == a["smooth"] and a["disagree"] == 0


def _onset_in_space(seed: int, mu: float = 0.4, e: float = 0.3):
    """One contact in space whose answer sticks exactly on the cone's rim (U_T = 0,
    |Λ_T| = μΛ_n), built backwards from that answer, with M and W coupling every row."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(3, 3))
    M = A @ A.T + 3 * np.eye(3)
    W = rng.normal(size=(3, 3)) + 2 * np.eye(3)
    G = W.T @ np.linalg.solve(M, W)
    t_hat = rng.normal(size=2)
    t_hat /= np.linalg.norm(t_hat)
    lam = np.array([1.0, *(mu * t_hat)])
    if (G @ lam)[0] <= 0:
        lam[1:] *= -1
    Gl = G @ lam
    U_minus = np.array([-Gl[0] / (1 + e), -Gl[1], -Gl[2]])  # U⁺ = (−eU⁻_n, 0, 0)
    u_minus = np.linalg.solve(W.T, U_minus)
    return iq.ImpactProblem(M, W, u_minus, contact_dim=3), iq.Coulomb(mu, e), lam, rng


@pytest.mark.parametrize("seed", range(4))
def test_coulomb_onset_in_space_both_sides(seed: int) -> None:
    """At the onset of sliding in space the one-sided derivatives follow the solve on each
    side: along −t̂ the slip starts and stays across t̂ at 0 to first order, so Λ_T turns
    (the slide's limit, not Λ_T ∥ t̂)."""
    p, law, lam, rng = _onset_in_space(seed)
    r = iq.solve(p, law)
    assert np.allclose(r.impulses, lam, atol=1e-9)
    d = r.derivative()
    assert d.status == "kink"
    seen = set()
    for _ in range(6):
        du = rng.normal(size=3)
        for sign in (1.0, -1.0):
            h = 1e-7
            moved = iq.solve(p.with_u_minus(p.u_minus + sign * h * du), law)
            fd = (moved.u_plus - r.u_plus) / h
            one_sided = d.directional(u_minus=sign * du).u_plus
            assert np.allclose(one_sided, fd, atol=2e-5 * np.linalg.norm(du)), (sign, du)
            W = p.W
            slip = W.T @ moved.u_plus
            seen.add(bool(np.linalg.norm(slip[1:]) > 1e-12))
    assert seen == {True, False}  # both the sticking and the sliding side were crossed
