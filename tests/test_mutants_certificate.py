"""The laws' certificate type (impactqp/laws/certificate.py), written to kill the mutants
benchmarks/mutation.py makes of it: the velocity-error bound of Moreau's law bounds the
error, a certificate cannot be altered once made, and ``certify`` takes ε and tol by name
only."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import impactqp as iq
from impactqp.laws.certificate import Certificate, certify


def _kinetic(problem, v: np.ndarray) -> float:
    M = problem.structure.M
    M = M.toarray() if hasattr(M, "toarray") else np.asarray(M)
    return float(np.sqrt(v @ M @ v))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_the_velocity_error_bound_bounds_the_error(seed: int) -> None:
    # docs/theory.md §3: ‖u⁺ − u⁺_exact‖ / V ≤ √(2 · duality_gap) for any candidate (u⁺, Λ)
    # with Λ ≥ 0 — here the exact answer with its impulses scaled, so u⁺ moves with them
    p = iq.random_impact(6, 4, seed=seed)
    eps = 0.5
    exact = iq.moreau(p, eps)
    V = _kinetic(p, p.u_minus)
    for factor in (0.9, 0.99, 1.05):
        lam = exact.impulses * factor
        up = exact.u_plus + (factor - 1.0) * (exact.u_plus - p.u_minus)
        cert = certify(p, up, lam, eps, eps=eps)
        bound = cert.velocity_error_bound
        error = _kinetic(p, up - exact.u_plus) / V
        assert error > 0.0
        assert error <= bound
        assert bound == pytest.approx(np.sqrt(2.0 * cert.duality_gap), rel=1e-12)
    assert 0.0 <= exact.certificate.velocity_error_bound < 1e-6


def test_only_moreaus_law_has_the_bound() -> None:
    p = iq.random_impact(5, 3, seed=4)
    r = iq.moreau(p, 0.5)
    assert r.certificate.velocity_error_bound is not None
    m = p.structure.m
    cert = certify(p, r.u_plus, r.impulses, 0.5 * np.ones(m))  # the local Newton residuals
    assert cert.duality_gap is None
    assert cert.velocity_error_bound is None


def test_a_certificate_cannot_be_altered() -> None:
    cert = Certificate({"momentum": 1e-3}, 1e-9)
    assert not cert.ok
    with pytest.raises(dataclasses.FrozenInstanceError):
        cert.tol = 1.0  # type: ignore[misc]
    assert not cert.ok


def test_certify_takes_eps_and_tol_by_name_only() -> None:
    # E and ε are both numbers for Moreau's law: a positional ε would be read silently
    p = iq.random_impact(5, 3, seed=5)
    r = iq.moreau(p, 0.5)
    with pytest.raises(TypeError):
        certify(p, r.u_plus, r.impulses, 0.5, 0.5)  # type: ignore[misc]
    assert certify(problem=p, u_plus=r.u_plus, impulses=r.impulses, E=0.5, eps=0.5).ok
