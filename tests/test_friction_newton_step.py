"""Newton's steps on frictional contact problems (docs/theory.md §23): the LU with diagonal
pivots in a minimum-degree order of J + Jᵀ, kept only when its step solves the system, else
scipy's LU with partial pivoting; and J assembled straight into compressed columns from W's
contact blocks."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import impactqp as iq
from benchmarks.friction_data import load
from impactqp.qp.friction import newton as newton_module
from impactqp.qp.friction.data import ContactBlocks
from impactqp.qp.friction.newton import (
    STEP_RESIDUAL,
    FrictionData,
    newton,
    newton_step,
)


def contact_jacobian(d: int, m: int, seed: int) -> tuple[sp.csc_matrix, np.ndarray]:
    """J = A + λI + B W of a random sparse symmetric positive semidefinite W of m contacts
    (some B_c = 0: contacts coming apart), and a right-hand side."""
    rng = np.random.default_rng(seed)
    H = sp.random(d * m, 2 * d * m, density=3.0 / m, random_state=seed, format="csr")
    W = sp.csr_matrix(H @ H.T + 1e-3 * sp.identity(d * m))
    A = rng.standard_normal((m, d, d))
    B = rng.standard_normal((m, d, d))
    B[::4] = 0.0
    A[::4] = np.eye(d)
    J = ContactBlocks.of(W, d).jacobian(A, B, 1e-2)
    return J, rng.standard_normal(d * m)


@pytest.mark.parametrize("d", [2, 3])
def test_step_solves_the_system_as_partial_pivoting_does(d: int) -> None:
    J, b = contact_jacobian(d, 40, seed=d)
    step = newton_step(J, b)
    assert np.linalg.norm(J @ step - b) <= STEP_RESIDUAL * np.linalg.norm(b)
    reference = spla.splu(J).solve(b)  # scipy's default: COLAMD, partial pivoting
    assert np.allclose(step, reference, rtol=1e-8, atol=1e-10 * np.abs(reference).max())


def test_a_zero_diagonal_falls_back_to_partial_pivoting() -> None:
    # a permutation: every diagonal pivot is zero, partial pivoting solves it exactly
    J = sp.csc_matrix(np.array([[0.0, 2.0, 0.0], [3.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
                      + np.diag([0.0, 0.0, 5.0]))
    b = np.array([4.0, 9.0, 10.0])
    assert np.allclose(newton_step(J, b), [3.0, 2.0, 2.0])


def test_an_inaccurate_diagonal_lu_falls_back(monkeypatch: pytest.MonkeyPatch) -> None:
    """A step from the diagonal-pivot LU that does not solve the system to STEP_RESIDUAL is
    not used: the system is solved again with partial pivoting."""
    J, b = contact_jacobian(3, 30, seed=7)
    calls: list[str] = []
    real = spla.splu

    class Wrong:
        def solve(self, rhs: np.ndarray) -> np.ndarray:
            return rhs * 0.5

    def splu(A: sp.csc_matrix, **options: object) -> object:
        calls.append(str(options.get("permc_spec", "COLAMD")))
        return Wrong() if options else real(A)

    monkeypatch.setattr(newton_module.spla, "splu", splu)
    step = newton_step(J, b)
    assert calls == ["MMD_AT_PLUS_A", "COLAMD"]
    assert np.linalg.norm(J @ step - b) <= 1e-10 * np.linalg.norm(b)


def test_an_exactly_singular_J_raises_for_the_caller() -> None:
    J = sp.csc_matrix(np.array([[1.0, 2.0], [2.0, 4.0]]))
    with pytest.raises(RuntimeError):
        newton_step(J, np.array([1.0, 0.0]))


@pytest.mark.parametrize("d", [2, 3])
def test_jacobian_is_sorted_compressed_columns_without_stored_zeros(d: int) -> None:
    J, _ = contact_jacobian(d, 25, seed=11 + d)
    assert J.format == "csc" and J.has_sorted_indices
    assert np.all(J.data != 0.0)
    J2, _ = contact_jacobian(d, 25, seed=11 + d)  # the blocks' index arrays are not shared
    assert np.array_equal(J.indices, J2.indices)


@pytest.mark.parametrize("name", ["Capsules", "FC2D-00237"])
def test_newton_certifies_file_problems_with_these_steps(name: str) -> None:
    """Newton from r = 0 with these steps certifies a 3-D and a 2-D FCLib problem; its answer
    passes the independent certificate on the problem as given, through the front door."""
    problem = load(name).problem
    data = FrictionData(problem.in_contact_units().problem)
    r, steps, ok = newton(data, np.zeros_like(data.q), 1e-8)
    assert ok and 0 < steps < 50
    result = iq.solve_friction(problem, backend="newton", tol=1e-8)
    assert result.certificate.ok and result.error <= 1e-8


def test_norm_is_the_euclidean_norm_of_long_vectors() -> None:
    """The friction methods' norm (summed without BLAS) agrees with numpy's, on vectors
    longer than OpenBLAS's threading threshold and on a zero vector."""
    rng = np.random.default_rng(3)
    for x in (rng.standard_normal(14004) * 1e-150, rng.standard_normal(7) * 1e150,
              np.zeros(20001), rng.standard_normal(20001)):
        assert newton_module.norm(x) == pytest.approx(float(np.linalg.norm(x)), rel=1e-13,
                                                      abs=0.0)
