"""The torch adapter (impactqp.interop.torch, the ``torch`` extra; docs/interop.rst):
gradcheck in double precision, gradients equal impactqp's own VJPs and central finite
differences, batches, the kink's default element, and refusals by name."""

from __future__ import annotations

import numpy as np
import pytest
from test_interop_imports import STOP, Stop, page_snippet

import impactqp as iq
from impactqp.errors import (
    CertificateError,
    DerivativeUnsupportedError,
    InputError,
    ShapeError,
)

torch = pytest.importorskip("torch")
from impactqp.interop.torch import ImpactFunction, impact_map  # noqa: E402

CRADLE = iq.newtons_cradle(3).with_u_minus([1.0, 0.1, -0.2])
RANDOM = iq.random_impact(7, 3, seed=4)
CASES = {"cradle-moreau": (CRADLE, iq.Moreau(0.5), "eps", 0.5),
         "cradle-newton": (CRADLE, iq.Newton([0.9, 0.4]), "e", [0.9, 0.4]),
         "random-moreau": (RANDOM, iq.Moreau(0.3), "eps", 0.3),
         "random-fremond": (RANDOM, iq.Fremond(0.4 * np.eye(3) + 0.05), "E",
                            0.4 * np.eye(3) + 0.05)}


def leaf(x) -> torch.Tensor:
    return torch.tensor(np.asarray(x, dtype=float), dtype=torch.float64, requires_grad=True)


@pytest.mark.parametrize("name", CASES)
def test_gradcheck_and_impactqps_vjp(name: str) -> None:
    problem, law, key, value = CASES[name]
    d = iq.derivative(problem, law)
    assert d.status == "smooth" and d.certificate.ok
    f = impact_map(problem, law, impulses=True)
    u, p = leaf(problem.u_minus), leaf(value)
    # torch's own check: the backward pass against its finite differences, in float64
    assert torch.autograd.gradcheck(lambda u, p: f(u, {key: p}), (u, p))
    w, c = np.linspace(1.0, 2.0, problem.n_dof), np.linspace(-1.0, 1.0, problem.n_impulses)
    u_plus, lam = f(u, {key: p})
    (u_plus @ torch.as_tensor(w) + lam @ torch.as_tensor(c)).backward()
    own = d.vjp(u_plus=w, impulses=c)
    assert np.allclose(u.grad.numpy(), own["u_minus"], rtol=1e-12, atol=1e-12)
    assert np.allclose(p.grad.numpy(), own[key], rtol=1e-12, atol=1e-12)
    # and against central differences of the solve itself
    h, fd = 1e-6, np.zeros(problem.n_dof)
    for i in range(problem.n_dof):
        e = np.zeros(problem.n_dof)
        e[i] = h
        plus, minus = (iq.solve(problem.with_u_minus(problem.u_minus + s * e), law)
                       for s in (1, -1))
        fd[i] = (w @ (plus.u_plus - minus.u_plus) + c @ (plus.impulses - minus.impulses)) / (2 * h)
    assert np.allclose(u.grad.numpy(), fd, atol=1e-7)


def test_a_batch_is_one_impact_per_row() -> None:
    problem, law, key, _ = CASES["random-moreau"]
    f = impact_map(problem, law)
    rng = np.random.default_rng(0)
    U = leaf(problem.u_minus + 0.01 * rng.normal(size=(3, problem.n_dof)))
    per_row, shared = leaf([0.2, 0.5, 0.8]), leaf(0.3)
    assert torch.autograd.gradcheck(lambda U, e: f(U, {key: e}), (U, per_row))
    assert torch.autograd.gradcheck(lambda U, e: f(U, {key: e}), (U, shared))
    f(U, {key: shared}).sum().backward()
    total = 0.0
    for i in range(3):
        own = iq.derivative(problem.with_u_minus(U[i].detach().numpy()), iq.Moreau(0.3)).vjp(
            u_plus=np.ones(problem.n_dof))
        assert np.allclose(U.grad[i].numpy(), own["u_minus"], atol=1e-12)
        total += own["eps"]
    assert np.isclose(shared.grad.item(), total, atol=1e-12)  # a shared ε sums its rows
    with pytest.raises(ShapeError, match="eps"):
        f(U, {key: leaf([0.1, 0.2])})


def test_kink_uses_the_default_element() -> None:
    # docs/theory.md §19: three equal balls, u⁻ = (1, 0, ½), ε = 0; contact 2 is degenerate
    problem = iq.newtons_cradle(3).with_u_minus([1.0, 0.0, 0.5])
    d = iq.derivative(problem, iq.Moreau(0.0))
    assert d.status == "kink"
    f = impact_map(problem, iq.Moreau(0.0))
    J = torch.autograd.functional.jacobian(f, torch.tensor(problem.u_minus)).numpy()
    assert np.allclose(J, d.jacobian(), atol=1e-12)
    assert np.allclose(J, [[0.5, 0.5, 0], [0.5, 0.5, 0], [0, 0, 1]], atol=1e-12)


def test_coulomb_gradients_in_mu_and_restitution() -> None:
    # a point mass sliding on a floor (docs/theory.md §18): ∂u⁺ₓ/∂μ = −(1 + e) = −1.3
    problem = iq.ImpactProblem(np.eye(2), np.array([[0.0, 1.0], [1.0, 0.0]]), [0.9, -1.0],
                               contact_dim=2)
    law = iq.Coulomb(0.5, 0.3, method="nsgs")  # a keyword the rebuilt law keeps
    f = impact_map(problem, law)
    assert f.parameters == {"mu": (), "restitution": ()}
    u, mu, e = leaf(problem.u_minus), leaf(0.5), leaf(0.3)
    assert torch.autograd.gradcheck(lambda u, mu, e: f(u, {"mu": mu, "restitution": e}),
                                    (u, mu, e))
    f(u, {"mu": mu, "restitution": e})[0].backward()
    assert np.isclose(mu.grad.item(), -1.3) and np.isclose(e.grad.item(), -0.5)
    d = iq.derivative(problem, law)
    assert np.allclose(u.grad.numpy(), d.jacobian()[0], atol=1e-12)


def test_a_users_hook_and_a_failed_derivative_certificate() -> None:
    u = leaf(STOP.u_minus)
    impact_map(STOP, Stop())(u).sum().backward()
    assert np.allclose(u.grad.numpy(), [1.0, 1.0])  # (I − wwᵀ/2)ᵀ𝟙, w = (1, −1)
    f = impact_map(STOP, Stop(residual=1.0))  # solves, but its derivative is not certified
    u = leaf(STOP.u_minus)
    out = f(u)
    with pytest.raises(CertificateError, match="derivative's certificate failed"):
        out.sum().backward()  # no gradient is returned
    assert u.grad is None


def test_the_autograd_function_itself() -> None:
    f = impact_map(CRADLE, iq.Moreau(0.5))
    u = leaf(CRADLE.u_minus)
    u_plus, lam = ImpactFunction.apply(f.impact_map, u, leaf(0.5))
    assert np.allclose(u_plus.detach().numpy(), iq.moreau(CRADLE, 0.5).u_plus)
    assert lam.shape == (2,)


def test_refusals_by_name() -> None:
    with pytest.raises(DerivativeUnsupportedError, match="LZB"):
        impact_map(CRADLE, iq.LZB(1e6))
    f = impact_map(CRADLE, iq.Moreau(0.5))
    with pytest.raises(ShapeError, match="u_minus"):
        f(torch.ones(4, dtype=torch.float64))
    with pytest.raises(InputError, match="'mu'"):
        f(torch.ones(3, dtype=torch.float64), {"mu": 0.5})
    u = leaf(CRADLE.u_minus)
    with pytest.raises(DerivativeUnsupportedError, match="first derivatives only"):
        torch.autograd.grad(f(u).sum(), u, create_graph=True)  # no second derivative
    with pytest.raises(DerivativeUnsupportedError, match="first derivatives only"):
        torch.autograd.functional.hessian(lambda u: f(u).square().sum(), u.detach())


def test_float32_in_float32_out() -> None:
    f = impact_map(iq.newtons_cradle(3), iq.Moreau(1.0))
    u = torch.tensor([1.0, 0.0, 0.0], dtype=torch.float32, requires_grad=True)
    out = f(u)
    out[2].backward()
    assert out.dtype == u.grad.dtype == torch.float32
    assert np.allclose(out.detach().numpy(), [-1 / 3, 2 / 3, 2 / 3], atol=1e-7)


def test_the_docs_snippet_runs_and_sums_the_rows(capsys) -> None:
    namespace: dict = {}
    exec(page_snippet("impactqp.interop.torch"), namespace)  # noqa: S102 (the page's code)
    assert capsys.readouterr().out.strip()
    U, e = namespace["U"].detach().numpy(), namespace["e"]
    total = np.zeros(2)
    for i in range(2):
        d = iq.derivative(iq.newtons_cradle(3).with_u_minus(U[i]), iq.Newton([0.9, 0.7]))
        own = d.vjp(u_plus=d.u_plus)  # ∂(½‖u⁺‖²) = u⁺
        assert np.allclose(namespace["U"].grad[i].numpy(), own["u_minus"], atol=1e-12)
        total += own["e"]
    assert np.allclose(e.grad.numpy(), total, atol=1e-12)
