"""Bad input gets a specific exception whose message says what to fix."""

import numpy as np
import pytest

import impactqp as iq


def test_shapes():
    with pytest.raises(iq.errors.ShapeError, match="u_minus"):
        iq.ImpactProblem(np.eye(3), np.ones((3, 2)), [1.0, 2.0])
    with pytest.raises(iq.errors.ShapeError, match="W"):
        iq.ImpactProblem(np.eye(3), np.ones((2, 2)), [1.0, 2.0, 3.0])
    with pytest.raises(iq.errors.ShapeError, match="square"):
        iq.ImpactProblem(np.ones((3, 2)), np.ones((3, 2)), [1.0, 2.0, 3.0])
    with pytest.raises(iq.errors.ShapeError, match="zero"):
        iq.ImpactProblem(np.eye(2), np.zeros((2, 1)), [1.0, 2.0])


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite(bad):
    with pytest.raises(iq.errors.NonFiniteError, match="u_minus"):
        iq.ImpactProblem(np.eye(2), np.ones((2, 1)), [bad, 0.0])
    M = np.eye(2)
    M[0, 0] = bad
    with pytest.raises(iq.errors.NonFiniteError, match="M"):
        iq.ImpactProblem(M, np.ones((2, 1)), [0.0, 0.0])
    with pytest.raises(iq.errors.NonFiniteError, match="W"):
        iq.ImpactProblem(np.eye(2), np.array([[bad], [1.0]]), [0.0, 0.0])


def test_mass_matrix():
    with pytest.raises(iq.errors.MassMatrixError, match="symmetric"):
        iq.ImpactProblem(np.array([[2.0, 1.0], [0.0, 2.0]]), np.ones((2, 1)), [0.0, 0.0])
    with pytest.raises(iq.errors.MassMatrixError, match="positive definite"):
        iq.ImpactProblem(np.array([[1.0, 2.0], [2.0, 1.0]]), np.ones((2, 1)), [0.0, 0.0])
    import scipy.sparse as sp
    with pytest.raises(iq.errors.MassMatrixError, match="positive definite"):
        iq.ImpactProblem(sp.csc_matrix(np.array([[1.0, 2.0], [2.0, 1.0]])), np.ones((2, 1)),
                         [0.0, 0.0])
    with pytest.raises(iq.errors.MassMatrixError):
        iq.chain([1.0, 1.0], [0.0, 0.0], sparse=True).with_u_minus([0, 0]) and \
            iq.ImpactProblem(sp.diags([1.0, -1.0]), np.ones((2, 1)), [0.0, 0.0])


@pytest.mark.parametrize("eps", [-0.1, 1.5, np.nan])
def test_restitution(eps):
    p = iq.newtons_cradle()
    with pytest.raises(iq.errors.RestitutionError, match="eps"):
        iq.moreau(p, eps)
    with pytest.raises(iq.errors.RestitutionError, match="e "):
        iq.newton(p, [0.5, eps])
    with pytest.raises(ValueError):  # input errors are ValueErrors too
        iq.moreau(p, eps)


def test_fremond_matrix_shape_and_newton_length():
    p = iq.newtons_cradle()
    with pytest.raises(iq.errors.ShapeError, match="E"):
        iq.fremond(p, np.eye(3))
    with pytest.raises(iq.errors.ShapeError, match="e"):
        iq.newton(p, [0.5, 0.5, 0.5])


def test_backend_names():
    p = iq.newtons_cradle()
    for name in ["gurobi", "cvxpy:NOPE", "qpsolvers:nope", "exact:x", 3]:
        with pytest.raises(iq.errors.UnknownBackendError):
            iq.moreau(p, 0.5, backend=name)
    with pytest.raises(iq.InputError, match="form"):
        iq.moreau(p, 0.5, form="sideways")


def test_builders():
    with pytest.raises(iq.InputError, match="masses"):
        iq.chain([1.0, -1.0], [0.0, 0.0])
    with pytest.raises(iq.InputError, match="released"):
        iq.newtons_cradle(3, released=3)
    with pytest.raises(iq.InputError, match="n_balls"):
        iq.newtons_cradle(1)
    with pytest.raises(iq.InputError, match="mass"):
        iq.newtons_cradle(3, mass=0.0)


def test_lcp_refusals():
    with pytest.raises(iq.errors.NonSymmetricLCPError, match="symmetric"):
        iq.solve_lcp([[1.0, 2.0], [0.0, 1.0]], [1.0, 1.0])
    with pytest.raises(iq.errors.NonConvexLCPError, match="semidefinite"):
        iq.solve_lcp([[1.0, 2.0], [2.0, 1.0]], [1.0, 1.0])
    with pytest.raises(iq.errors.ShapeError, match="q"):
        iq.solve_lcp(np.eye(2), [1.0])


def test_membership_method_and_point_shape():
    S = iq.newtons_cradle().admissible_set()
    with pytest.raises(iq.InputError, match="method"):
        S.contains([0, 0, 1], method="guess")
    with pytest.raises(iq.errors.ShapeError, match="u"):
        S.contains([0, 1])


def test_every_error_is_an_impact_error():
    for cls in (iq.errors.ShapeError, iq.errors.NonFiniteError, iq.errors.MassMatrixError,
                iq.errors.RestitutionError,
                iq.errors.UnknownBackendError, iq.errors.NonSymmetricLCPError, iq.SolverError,
                iq.NoSolutionError, iq.CertificateError):
        assert issubclass(cls, iq.ImpactError)
