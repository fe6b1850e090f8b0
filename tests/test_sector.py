"""Tests of the N-ball sector law (docs/theory.md §5–§7)."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest
import scipy.linalg
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from impactqp.tables.certificate import (
    copositive_2x2,
    copositivity_margins,
    identify_rays,
    neighbour_pairs,
    velocity_matrices,
)
from impactqp.tables.sector_table import (
    SectorInputError,
    SectorTable,
    SectorTableTooLarge,
    chain_matrices,
    format_sector_table,
    make_cone,
    permutation_matrix,
    sector_gamma_map,
    sector_law_table,
    sector_velocity_map,
)

RNG = np.random.default_rng(20240611)


def gamma_of(u: np.ndarray) -> np.ndarray:
    return np.diff(np.asarray(u, dtype=float), axis=-1)


def relative_energy(u: np.ndarray, mass: float = 1.0) -> float:
    """Twice the centre-of-mass-free kinetic energy, m Σ (u_i − ū)²."""
    u = np.asarray(u, dtype=float)
    return float(mass * np.sum((u - u.mean()) ** 2))


def neighbour_swaps(u: np.ndarray) -> np.ndarray:
    """Independent reference: elastic collisions of equal neighbours swap velocities."""
    u = [float(x) for x in u]
    changed = True
    while changed:
        changed = False
        for i in range(len(u) - 1):
            if u[i] > u[i + 1]:  # approaching: they collide and exchange velocities
                u[i], u[i + 1] = u[i + 1], u[i]
                changed = True
    return np.array(u)


def broken(table: SectorTable, index: int, delta: float = 1e-3) -> SectorTable:
    cones = list(table.cones)
    Q = cones[index].Q.copy()
    Q[0, -1] += delta
    cones[index] = replace(cones[index], Q=Q)
    return SectorTable(cones=cones, G=table.G, W=table.W, n_balls=table.n_balls)


# --------------------------------------------------------------------------- structure
def test_three_balls_six_cones_cover_the_plane() -> None:
    table = sector_law_table(3)
    assert len(table.cones) == 6
    samples = np.vstack([RNG.normal(size=(500, 2)),
                         [[0, 1], [1, 0], [0, -1], [-1, 0], [1, -1], [-1, 1], [0, 0]]])
    inside = np.array([cone.contains(samples) for cone in table.cones])  # (6, k)
    assert inside.any(axis=0).all()
    # generic points lie in exactly one cone
    assert (inside[:, :500].sum(axis=0) == 1).all()


def test_three_ball_boundaries_are_the_three_lines() -> None:
    # every facet normal of every cone is ±(1,0), ±(0,1) or ±(1,1): γ1=0, γ2=0, γ1+γ2=0
    normals = {tuple(row) for cone in sector_law_table(3).cones for row in cone.inequalities}
    assert normals == {(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1)}


def test_identity_cone_is_first_orthant_with_Q_identity() -> None:
    for n in (2, 3, 5):
        cone = next(c for c in sector_law_table(n).cones if c.permutation == tuple(range(n)))
        np.testing.assert_array_equal(cone.Q, np.eye(n - 1))
        np.testing.assert_array_equal(cone.inequalities, np.eye(n - 1))
        np.testing.assert_allclose(cone.rays, np.eye(n - 1))


@pytest.mark.parametrize("n", [3, 4, 5])
def test_cone_geometry(n: int) -> None:
    table = sector_law_table(n)
    assert len(table.cones) == math.factorial(n)
    ids, unit = identify_rays(np.stack([c.rays for c in table.cones]))
    assert len(unit) == 2**n - 2  # one ray per nonempty proper "top" set of balls
    pairs, _ = neighbour_pairs(ids)
    assert len(pairs) == math.factorial(n) * (n - 1) // 2
    for cone in table.cones:
        np.testing.assert_allclose(np.linalg.norm(cone.rays, axis=1), 1.0)
        slack = cone.rays @ cone.inequalities.T  # H r_k ∝ e_k: each ray on n−2 facets
        assert np.all(slack >= -1e-12)
        np.testing.assert_allclose(slack, np.diag(np.diag(slack)), atol=1e-12)
        # the slacks of the ordering inequalities are the post-impact gaps
        np.testing.assert_allclose(cone.inequalities, cone.Q, atol=1e-12)


def test_batched_build_matches_single_cone_derivation() -> None:
    for cone in sector_law_table(5).cones[::7]:
        single = make_cone(cone.permutation)
        assert single.label == cone.label
        for attr in ("rays", "Q", "inequalities"):
            np.testing.assert_allclose(getattr(single, attr), getattr(cone, attr), atol=1e-12)


def test_delassus_matrix_of_reference_cradle() -> None:
    _, W, G = chain_matrices(3, mass=2.0)
    np.testing.assert_array_equal(W, [[-1, 0], [1, -1], [0, 1]])
    np.testing.assert_allclose(G, 0.5 * np.array([[2, -1], [-1, 2]]))


# --------------------------------------------------------------------------- the law
def test_classic_cradle() -> None:
    v = 1.7
    table = sector_law_table(3)
    g_minus = gamma_of([v, 0, 0])
    np.testing.assert_allclose(g_minus, [-v, 0])
    np.testing.assert_allclose(table.apply(g_minus), [0, v])
    np.testing.assert_allclose(sector_gamma_map(g_minus), [0, v])
    np.testing.assert_allclose(sector_velocity_map([v, 0, 0]), [0, 0, v])
    assert table.cones[table.find_cone(g_minus)].label in {"u2 ≤ u3 ≤ u1", "u3 ≤ u2 ≤ u1"}


def test_five_balls_two_released() -> None:
    v = 2.0
    u_minus = np.array([v, v, 0, 0, 0])
    np.testing.assert_allclose(sector_velocity_map(u_minus), [0, 0, 0, v, v])
    expected = gamma_of([0, 0, 0, v, v])
    np.testing.assert_allclose(sector_gamma_map(gamma_of(u_minus)), expected)
    np.testing.assert_allclose(sector_law_table(5).apply(gamma_of(u_minus)), expected)


def test_random_velocities_get_sorted_like_neighbour_swaps() -> None:
    for n in range(2, 8):
        u = RNG.normal(size=(20, n))
        out = sector_velocity_map(u)
        assert np.all(np.diff(out, axis=-1) >= 0)
        for row, row_out in zip(u, out):
            np.testing.assert_array_equal(row_out, neighbour_swaps(row))


@pytest.mark.parametrize("n", [3, 4, 5, 6])
def test_table_apply_agrees_with_sort_map(n: int) -> None:
    table = sector_law_table(n)
    g = RNG.normal(size=(300, n - 1))
    g[:30, 0] = 0.0  # on boundaries
    g[30:60, -1] = -g[30:60, 0] if n > 2 else 0.0
    expected = sector_gamma_map(g)
    np.testing.assert_allclose(table.apply(g), expected, atol=1e-12)
    for row in g[::37]:
        np.testing.assert_allclose(table.apply(row), sector_gamma_map(row), atol=1e-12)


@pytest.mark.parametrize("n", [3, 5])
def test_every_containing_cone_gives_the_same_value(n: int) -> None:
    table = sector_law_table(n)
    u = RNG.integers(0, 3, size=(40, n)).astype(float)  # many ties: boundary points
    for g in gamma_of(u):
        values = [c.Q @ g for c in table.cones if c.contains(g)]
        assert len(values) >= 1
        np.testing.assert_allclose(values, [sector_gamma_map(g)] * len(values), atol=1e-12)


def test_three_ball_pieces_map_into_first_quadrant() -> None:
    table = sector_law_table(3)
    assert sum(not np.array_equal(c.Q, np.eye(2)) for c in table.cones) == 5
    for cone in table.cones:
        assert np.all(cone.Q @ cone.rays.T >= 0)
    assert np.all(table.apply(RNG.normal(size=(200, 2))) >= 0)


def test_velocity_map_of_each_piece_is_its_permutation() -> None:
    table = sector_law_table(4)
    M, W, G = chain_matrices(4)
    A = velocity_matrices(np.stack([c.Q for c in table.cones]), W, G, M)
    for cone, a in zip(table.cones, A):
        np.testing.assert_allclose(a, permutation_matrix(cone.permutation), atol=1e-12)


def test_errors() -> None:
    with pytest.raises(SectorTableTooLarge, match="sector_gamma_map"):
        sector_law_table(9)
    assert issubclass(SectorTableTooLarge, ValueError)
    with pytest.raises(SectorInputError):
        sector_law_table(1)
    with pytest.raises(SectorInputError):
        sector_law_table(3, mass=0.0)
    with pytest.raises(SectorInputError):
        sector_law_table(3).apply(np.zeros(3))
    # no table needed for large n
    u = RNG.normal(size=50)
    np.testing.assert_allclose(sector_gamma_map(gamma_of(u)), gamma_of(np.sort(u)))


# --------------------------------------------------------------------------- certificate
@pytest.mark.parametrize("n", [3, 4, 5, 6])
def test_certificate_passes(n: int) -> None:
    cert = sector_law_table(n).certificate
    for check in cert.checks:
        assert check.passed, check
    assert cert.continuity.margin <= 1e-12
    assert cert.non_expansive.margin == pytest.approx(1.0, abs=1e-12)
    assert cert.velocity_non_expansive.margin == pytest.approx(1.0, abs=1e-12)
    assert cert.maximal_monotone and cert.admissible
    assert "maximal monotone" in cert.reason
    assert cert.n_neighbour_pairs == math.factorial(n) * (n - 1) // 2
    assert len(cert.cones) == math.factorial(n)


def test_certificate_is_lazy_and_cached() -> None:
    table = sector_law_table(3)
    assert "certificate" not in table.__dict__
    assert table.certificate is table.certificate


def test_energetic_consistency_is_conservation() -> None:
    table = sector_law_table(4, mass=3.0)
    Gi = np.linalg.inv(table.G)
    for cone in table.cones:
        np.testing.assert_allclose(cone.Q.T @ Gi @ cone.Q, Gi, atol=1e-12)
    cert = table.certificate
    assert cert.energetic.passed and abs(cert.energetic.margin) <= 1e-12
    assert cert.kinetic.passed and cert.kinematic.passed


@pytest.mark.parametrize("index", [0, 3, 5])
def test_broken_table_is_caught_naming_the_cone(index: int) -> None:
    table = sector_law_table(3)
    bad = broken(table, index)
    cert = bad.certificate
    assert not cert.continuity.passed
    assert not cert.maximal_monotone
    assert bad.cones[index].label in cert.reason
    assert cert.continuity.margin == pytest.approx(1e-3 / math.sqrt(2), rel=1e-6) or \
        cert.continuity.margin == pytest.approx(1e-3, rel=1e-6)
    assert sector_law_table(3).certificate.maximal_monotone  # the original is untouched


def test_broken_table_in_four_balls() -> None:
    table = sector_law_table(4)
    bad = broken(table, 17, delta=1e-6)
    assert not bad.certificate.maximal_monotone
    assert table.cones[17].label in bad.certificate.reason


def test_expanding_but_continuous_law_fails_non_expansiveness() -> None:
    table = sector_law_table(3)
    cones = [replace(c, Q=1.1 * c.Q) for c in table.cones]
    cert = SectorTable(cones=cones, G=table.G, W=table.W, n_balls=3).certificate
    assert cert.continuity.passed
    assert not cert.non_expansive.passed and cert.non_expansive.margin == pytest.approx(1.21)
    assert not cert.energetic.passed and cert.energetic.margin < 0
    assert not cert.maximal_monotone and "expands" in cert.reason
    assert not cert.admissible and "energetic consistency fails" in cert.reason


def test_expansion_matches_scipy_generalized_eigenvalues() -> None:
    table = sector_law_table(3)
    Gi = np.linalg.inv(table.G)
    for cone, check in zip(table.cones, table.certificate.cones):
        lam = scipy.linalg.eigh(cone.Q.T @ Gi @ cone.Q, Gi, eigvals_only=True)
        assert check.expansion == pytest.approx(lam.max(), abs=1e-12)
        assert check.label == cone.label


def test_large_tables_certify_quickly() -> None:
    cert = sector_law_table(7).certificate
    assert cert.maximal_monotone and cert.energetic.passed and cert.kinetic.passed


# --------------------------------------------------------------------------- copositivity
def test_copositivity_2x2_closed_form_agrees_with_enumeration() -> None:
    C = RNG.normal(size=(400, 2, 2))
    C = C + np.swapaxes(C, 1, 2)
    margins = copositivity_margins(C)
    for c, m in zip(C, margins):
        assert copositive_2x2(c, tol=0.0) == (m >= 0)


def test_copositivity_margin_is_the_minimum_over_the_cone() -> None:
    horn = np.array([[1, -1, 1, 1, -1], [-1, 1, -1, 1, 1], [1, -1, 1, -1, 1],
                     [1, 1, -1, 1, -1], [-1, 1, 1, -1, 1]], dtype=float)
    assert np.linalg.eigvalsh(horn)[0] < 0  # not PSD, yet copositive
    assert copositivity_margins(horn[None])[0] >= -1e-12
    not_cop = horn.copy()
    not_cop[0, 1] = not_cop[1, 0] = -1.2
    assert copositivity_margins(not_cop[None])[0] < 0
    C = RNG.normal(size=(30, 3, 3))
    C = C + np.swapaxes(C, 1, 2)
    k = 300  # grid on the simplex, faces included, projected to the sphere
    x = np.array([(i, j, k - i - j) for i in range(k + 1) for j in range(k + 1 - i)], float)
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    sampled = np.einsum("si,kij,sj->ks", x, C, x).min(axis=1)
    exact = copositivity_margins(C)
    assert np.all(exact <= sampled + 1e-12)
    np.testing.assert_allclose(exact, sampled, atol=2e-3)


# --------------------------------------------------------------------------- properties
gammas = st.integers(2, 9).flatmap(
    lambda n: arrays(np.float64, n - 1, elements=st.floats(-1e3, 1e3, allow_subnormal=False))
)


@settings(max_examples=200, deadline=None)
@given(gammas, st.floats(0.1, 10.0))
def test_gamma_plus_admissible_and_energy_conserved(g: np.ndarray, mass: float) -> None:
    n = g.size + 1
    _, _, G = chain_matrices(n, mass)
    Gi = np.linalg.inv(G)
    gp = sector_gamma_map(g)
    assert np.all(gp >= 0)
    u = np.concatenate([[0.0], np.cumsum(g)])
    # γᵀG⁻¹γ only sees relative motion: it is twice the centre-of-mass-free energy
    scale = 1e-9 * max(1.0, relative_energy(u, mass))
    assert g @ Gi @ g == pytest.approx(relative_energy(u, mass), abs=scale)
    assert gp @ Gi @ gp == pytest.approx(g @ Gi @ g, abs=scale)
    up = sector_velocity_map(u)
    assert relative_energy(up, mass) == pytest.approx(relative_energy(u, mass), abs=scale)


@settings(max_examples=200, deadline=None)
@given(st.integers(2, 9).flatmap(lambda n: st.tuples(
    arrays(np.float64, n - 1, elements=st.floats(-100, 100, allow_subnormal=False)),
    arrays(np.float64, n - 1, elements=st.floats(-100, 100, allow_subnormal=False)))))
def test_non_expansive_on_pairs(pair: tuple[np.ndarray, np.ndarray]) -> None:
    a, b = pair
    _, _, G = chain_matrices(a.size + 1)
    Gi = np.linalg.inv(G)
    d_out = sector_gamma_map(a) - sector_gamma_map(b)
    d_in = a - b
    assert d_out @ Gi @ d_out <= d_in @ Gi @ d_in * (1 + 1e-9) + 1e-9


def test_batch_axes() -> None:
    g = RNG.normal(size=(4, 5, 3))
    out = sector_gamma_map(g)
    assert out.shape == g.shape
    for idx in itertools.product(range(4), range(5)):
        np.testing.assert_allclose(out[idx], sector_gamma_map(g[idx]))


# --------------------------------------------------------------------------- formatting
def test_format_three_ball_table() -> None:
    text = format_sector_table(sector_law_table(3))
    for cone in sector_law_table(3).cones:
        assert cone.label in text
    row = next(line for line in text.splitlines() if line.startswith("u2 ≤ u3 ≤ u1"))
    assert "[0 1; -1 -1]" in row
    assert "maximal monotone: True" in text
    half = format_sector_table(sector_law_table(3, mass=2.0), include_certificate=False)
    assert "[1 -1/2; -1/2 1]" in half and "Certificate" not in half
