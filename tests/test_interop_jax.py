"""The jax adapter (impactqp.interop.jax, the ``jax`` extra; docs/interop.rst): gradients equal
impactqp's own Jacobians and central finite differences of the solve, jit equals eager,
vmap equals rows, the kink's default element, and refusals by name."""

from __future__ import annotations

import numpy as np
import pytest
from test_interop_imports import STOP, Stop, page_snippet

import impactqp as iq
from impactqp.errors import DerivativeUnsupportedError, InputError, ShapeError

jax = pytest.importorskip("jax")
jnp = jax.numpy
from impactqp.interop.jax import impact_map  # noqa: E402  (after the extra is found)


@pytest.fixture(autouse=True)
def float64():
    """Double precision for each test, the setting restored after it."""
    before = jax.config.jax_enable_x64
    jax.config.update("jax_enable_x64", True)
    yield
    jax.config.update("jax_enable_x64", before)


def cases() -> list[tuple[str, iq.ImpactProblem, iq.ImpactLaw, dict]]:
    """A 3-ball cradle and random impacts, each at a smooth point (asserted below)."""
    cradle = iq.newtons_cradle(3).with_u_minus([1.0, 0.1, -0.2])
    random = iq.random_impact(7, 3, seed=4)
    return [("cradle-moreau", cradle, iq.Moreau(0.5), {"eps": 0.5}),
            ("cradle-newton", cradle, iq.Newton([0.9, 0.4]), {"e": np.array([0.9, 0.4])}),
            ("random-moreau", random, iq.Moreau(0.3), {"eps": 0.3}),
            ("random-fremond", random, iq.Fremond(0.4 * np.eye(3) + 0.05),
             {"E": 0.4 * np.eye(3) + 0.05})]


CASES = {name: case for name, *case in cases()}


def central(f, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """∂f/∂x by central differences, one column per entry of x."""
    cols = []
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = h
        cols.append((np.asarray(f(x + e.reshape(x.shape))) -
                     np.asarray(f(x - e.reshape(x.shape)))) / (2 * h))
    return np.stack(cols, axis=-1)


@pytest.mark.parametrize("name", CASES)
def test_gradients_are_impactqps_vjp_and_central_differences(name: str) -> None:
    problem, law, params = CASES[name]
    d = iq.derivative(problem, law)
    assert d.status == "smooth" and d.certificate.ok
    f = impact_map(problem, law)
    (key, value), = params.items()
    assert f.parameters == {key: np.shape(value)}
    u = problem.u_minus
    w = np.linspace(1.0, 2.0, problem.n_dof)  # a loss ⟨w, u⁺⟩
    grad_u, grad_p = jax.grad(lambda u, p: jnp.dot(w, f(u, p)), argnums=(0, 1))(
        jnp.asarray(u), {key: jnp.asarray(value)})
    own = d.vjp(u_plus=w)
    assert np.allclose(grad_u, own["u_minus"], rtol=1e-12, atol=1e-12)
    assert np.allclose(grad_p[key], own[key], rtol=1e-12, atol=1e-12)
    # the full Jacobians: jacrev against impactqp's and against the solve's differences
    J = jax.jacrev(f)(jnp.asarray(u))
    assert np.allclose(J, d.jacobian("u_minus"), atol=1e-12)
    fd = central(lambda x: f(jnp.asarray(x)), u)
    assert np.allclose(J, fd, atol=1e-7)
    Jp = jax.jacrev(lambda p: f(jnp.asarray(u), {key: p}))(jnp.asarray(value, dtype=float))
    assert np.allclose(Jp, d.jacobian(key), atol=1e-12)
    fdp = central(lambda p: f(jnp.asarray(u), {key: jnp.asarray(p)}),
                  np.asarray(value, dtype=float))
    assert np.allclose(Jp, fdp.reshape(Jp.shape), atol=1e-7)


def test_impulses_carry_their_cotangent() -> None:
    problem, law, _ = CASES["random-moreau"]
    f = impact_map(problem, law, impulses=True)
    d = iq.derivative(problem, law)
    u_plus, lam = f(jnp.asarray(problem.u_minus))
    assert np.allclose(u_plus, d.u_plus) and np.allclose(lam, d.impulses)
    c = np.array([1.0, -2.0, 0.5])
    g = jax.grad(lambda u: jnp.dot(c, f(u)[1]))(jnp.asarray(problem.u_minus))
    assert np.allclose(g, d.vjp(impulses=c)["u_minus"], atol=1e-12)
    assert np.allclose(g, central(lambda x: f(jnp.asarray(x))[1], problem.u_minus).T @ c,
                       atol=1e-7)


def test_jit_agrees_with_eager() -> None:
    problem, law, params = CASES["cradle-newton"]
    f = impact_map(problem, law)

    def loss(u, p):
        return jnp.sum(f(u, p) ** 2)

    u, p = jnp.asarray(problem.u_minus), {"e": jnp.asarray(params["e"])}
    eager = jax.value_and_grad(loss, argnums=(0, 1))(u, p)
    jitted = jax.jit(jax.value_and_grad(loss, argnums=(0, 1)))(u, p)
    assert np.isclose(eager[0], jitted[0], rtol=1e-14)
    assert np.allclose(eager[1][0], jitted[1][0], rtol=1e-14)
    assert np.allclose(eager[1][1]["e"], jitted[1][1]["e"], rtol=1e-14)


def test_vmap_is_one_impact_per_row() -> None:
    problem, law, _ = CASES["random-moreau"]
    f = impact_map(problem, law)
    rng = np.random.default_rng(0)
    U = problem.u_minus + 0.01 * rng.normal(size=(4, problem.n_dof))
    eps = np.array([0.1, 0.3, 0.6, 0.9])
    loss = jax.jit(jax.vmap(jax.grad(lambda u, e: jnp.sum(f(u, {"eps": e})), argnums=(0, 1))))
    gu, ge = loss(jnp.asarray(U), jnp.asarray(eps))
    for i in range(4):
        d = iq.derivative(problem.with_u_minus(U[i]), iq.Moreau(eps[i]))
        own = d.vjp(u_plus=np.ones(problem.n_dof))
        assert np.allclose(gu[i], own["u_minus"], atol=1e-12)
        assert np.isclose(ge[i], own["eps"], atol=1e-12)


@pytest.mark.parametrize("name", ["cradle-newton", "random-fremond"])
def test_forward_mode_is_impactqps_jvp(name: str) -> None:
    problem, law, params = CASES[name]
    (key, value), = params.items()
    d = iq.derivative(problem, law)
    f = impact_map(problem, law, mode="forward", impulses=True)
    u = jnp.asarray(problem.u_minus)
    J = jax.jacfwd(lambda u: f(u)[0])(u)
    assert np.allclose(J, d.jacobian("u_minus"), atol=1e-12)
    rng = np.random.default_rng(3)
    du, dp = rng.normal(size=problem.n_dof), rng.normal(size=np.shape(value))
    out, tangent = jax.jit(lambda u, p, du, dp: jax.jvp(lambda u, p: f(u, {key: p}), (u, p),
                                                         (du, dp)))(
        u, jnp.asarray(value), jnp.asarray(du), jnp.asarray(dp))
    own = d.jvp(u_minus=du, **{key: dp})
    assert np.allclose(tangent[0], own.u_plus, atol=1e-12)
    assert np.allclose(tangent[1], own.impulses, atol=1e-12)
    # the same numbers as reverse mode's VJP: ⟨w, J du⟩ = ⟨Jᵀw, du⟩
    w = np.linspace(1.0, 2.0, problem.n_dof)
    back = d.vjp(u_plus=w)
    assert np.isclose(w @ tangent[0], back["u_minus"] @ du + np.sum(back[key] * dp),
                      rtol=1e-10)
    rows = jax.vmap(lambda du: jax.jvp(lambda u: f(u)[0], (u,), (du,))[1])(jnp.eye(problem.n_dof))
    assert np.allclose(rows.T, J, atol=1e-12)
    with pytest.raises(ValueError, match="callbacks do not support transpose"):
        jax.grad(lambda u: jnp.sum(f(u)[0]))(u)  # reverse mode is the other function


def test_kink_uses_the_default_element() -> None:
    # docs/theory.md §19: three equal balls, u⁻ = (1, 0, ½), ε = 0; contact 2 is degenerate
    problem = iq.newtons_cradle(3).with_u_minus([1.0, 0.0, 0.5])
    d = iq.derivative(problem, iq.Moreau(0.0))
    assert d.status == "kink" and d.kink.contacts.tolist() == [1]
    f = impact_map(problem, iq.Moreau(0.0))
    J = np.asarray(jax.jacrev(f)(jnp.asarray(problem.u_minus)))
    assert np.allclose(J, d.jacobian(), atol=1e-12)  # the default element, S = ∅
    e3 = np.array([0, 0, 1.0])  # = the one-sided derivative along +e₃, not along −e₃
    assert np.allclose(J @ e3, d.directional(u_minus=e3).u_plus, atol=1e-12)
    assert np.allclose(J @ e3, [0, 0, 1], atol=1e-12)
    assert not np.allclose(J @ -e3, d.directional(u_minus=-e3).u_plus)
    assert np.allclose(J, [[0.5, 0.5, 0], [0.5, 0.5, 0], [0, 0, 1]], atol=1e-12)
    # ∂u⁺/∂ε = z − u⁻ on both sides of the kink
    assert np.allclose(jax.jacrev(lambda e: f(jnp.asarray(problem.u_minus), {"eps": e}))(0.0),
                       [-0.5, 0.5, 0.0], atol=1e-12)


def test_sector_law_is_a_permutation_with_the_stable_sort_at_ties() -> None:
    # docs/theory.md §19: u⁺ = Pu⁻, P the sorting permutation; at a tie, the stable sort
    problem = iq.newtons_cradle(3).with_u_minus([1.0, 0.5, 0.5])
    d = iq.derivative(problem, iq.SectorLaw())
    assert d.status == "kink"
    f = impact_map(problem, iq.SectorLaw())
    assert f.parameters == {}
    J = np.asarray(jax.jacrev(f)(jnp.asarray(problem.u_minus)))
    assert np.allclose(J, d.jacobian(), atol=0)
    assert set(np.unique(J)) == {0.0, 1.0} and np.all(J.sum(axis=0) == 1)  # a permutation
    assert any(np.array_equal(J, L) for L in d.limiting_jacobians())


def test_a_failed_derivative_certificate_stops_the_gradient() -> None:
    g = jax.grad(lambda u: jnp.sum(impact_map(STOP, Stop())(u)))(jnp.asarray(STOP.u_minus))
    assert np.allclose(g, [1.0, 1.0])  # a user's hook: (I − wwᵀ/2)ᵀ𝟙, w = (1, −1)
    f = impact_map(STOP, Stop(residual=1.0))  # solves, but its derivative is not certified
    assert np.allclose(f(jnp.asarray(STOP.u_minus)), [0.0, 0.0])
    with pytest.raises(Exception, match="derivative's certificate failed"):  # jax's error,
        jax.grad(lambda u: jnp.sum(f(u)))(jnp.asarray(STOP.u_minus))  # impactqp's message


def test_unsupported_laws_and_bad_input_are_refused_by_name() -> None:
    cradle = iq.newtons_cradle(3)  # (the LZB model, refused alike: tests/test_interop_torch.py)
    with pytest.raises(DerivativeUnsupportedError, match="reflection"):
        impact_map(cradle, iq.ReflectionLaw())
    f = impact_map(cradle, iq.Moreau(0.5))
    with pytest.raises(ShapeError, match="u_minus"):
        f(jnp.ones(4))
    with pytest.raises(InputError, match="'e'"):
        f(jnp.ones(3), {"e": 0.5})
    with pytest.raises(ShapeError, match="eps"):
        f(jnp.ones(3), {"eps": jnp.ones(2)})
    with pytest.raises(TypeError, match="forward-mode"):  # mode="forward" is another function
        jax.jvp(f, (jnp.ones(3),), (jnp.ones(3),))
    with pytest.raises(InputError, match="mode"):
        impact_map(cradle, iq.Moreau(0.5), mode="both")
    with pytest.raises(ValueError, match="callbacks do not support JVP"):  # no 2nd derivative
        jax.grad(lambda u: jnp.sum(jax.grad(lambda v: jnp.sum(f(v) ** 2))(u)))(jnp.ones(3))


def test_float32_in_float32_out() -> None:
    f = impact_map(iq.newtons_cradle(3), iq.Moreau(1.0))
    jax.config.update("jax_enable_x64", False)  # the fixture sets it back
    out = f(jnp.asarray([1.0, 0.0, 0.0], dtype=jnp.float32))
    g = jax.grad(lambda u: f(u)[2])(jnp.asarray([1.0, 0.0, 0.0], dtype=jnp.float32))
    assert out.dtype == jnp.float32 and g.dtype == jnp.float32
    assert np.allclose(out, [-1 / 3, 2 / 3, 2 / 3], atol=1e-7)


def test_the_docs_snippet_identifies_eps(capsys) -> None:
    namespace: dict = {}
    exec(page_snippet("impactqp.interop.jax"), namespace)  # noqa: S102 (the page's own code)
    assert capsys.readouterr().out.strip() == "eps = 0.800000"
    assert abs(float(namespace["eps"]) - 0.8) < 1e-12
