"""Every public entry point refuses bad input with an ImpactError that is a ValueError and
names the argument: NaN/inf, complex, object, None, strings, booleans, ragged lists, wrong
shapes — never a TypeError, an AttributeError or a silently truncated value."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import impactqp as iq

CRADLE = iq.newtons_cradle(3)
M3, W3 = np.eye(3), np.array([[-1.0, 0.0], [1.0, -1.0], [0.0, 1.0]])

BAD_VECTORS = {
    "nan": [np.nan, 0.0, 0.0],
    "inf": [np.inf, 0.0, 0.0],
    "complex": np.array([1 + 1j, 0, 0]),
    "object": np.array([1.0, object(), 0.0], dtype=object),
    "none": None,
    "string": "1,0,0",
    "strings": ["1", "0", "0"],
    "booleans": [True, False, False],
    "ragged": [[1.0, 2.0], [3.0]],
    "short": [1.0, 0.0],
    "matrix": [[1.0, 0.0, 0.0]],
}


def refuses(call: Callable[[], object], name: str) -> None:
    with pytest.raises(iq.ImpactError) as info:
        call()
    assert isinstance(info.value, ValueError), type(info.value)
    assert name in str(info.value), str(info.value)


@pytest.mark.parametrize("kind", list(BAD_VECTORS))
def test_pre_impact_velocity(kind: str) -> None:
    bad = BAD_VECTORS[kind]
    refuses(lambda: iq.ImpactProblem(M3, W3, bad), "u_minus")
    refuses(lambda: CRADLE.with_u_minus(bad), "u_minus")
    refuses(lambda: iq.chain([1.0, 1.0, 1.0], bad), "u_minus")


@pytest.mark.parametrize("kind", list(BAD_VECTORS))
def test_candidate_velocities(kind: str) -> None:
    bad = BAD_VECTORS[kind]
    refuses(lambda: CRADLE.admissible_set().contains(bad), "u")
    refuses(lambda: iq.classify(CRADLE, bad), "u_plus")
    refuses(lambda: CRADLE.admissible_set().project(bad), "point")


@pytest.mark.parametrize("kind", ["nan", "complex", "object", "none", "string", "booleans",
                                  "ragged"])
def test_matrices(kind: str) -> None:
    bad_entry = {"nan": np.nan, "complex": 1j, "object": object(), "none": None,
                 "string": "x", "booleans": True, "ragged": None}[kind]
    if kind == "ragged":
        M = [[1.0, 0.0, 0.0], [0.0, 1.0], [0.0, 0.0, 1.0]]
    else:
        M = np.eye(3).astype(object)
        M[0, 1] = M[1, 0] = bad_entry
        M = M.tolist()
    refuses(lambda: iq.ImpactProblem(M, W3, [1.0, 0.0, 0.0]), "M")
    refuses(lambda: iq.ImpactProblem(M3, M, [1.0, 0.0, 0.0]), "W")
    refuses(lambda: iq.solve_lcp(M, [1.0, 0.0, 0.0]), "G")


def test_shapes_and_mass_matrix() -> None:
    refuses(lambda: iq.ImpactProblem(np.eye(3), np.ones((2, 1)), [1, 0, 0]), "W")
    refuses(lambda: iq.ImpactProblem(np.ones((3, 2)), W3, [1, 0, 0]), "M")
    refuses(lambda: iq.ImpactProblem(-np.eye(3), W3, [1, 0, 0]), "M")
    refuses(lambda: iq.ImpactProblem(np.array([[1, 2, 0], [0, 1, 0], [0, 0, 1.0]]), W3,
                                     [1, 0, 0]), "M")
    refuses(lambda: iq.solve_lcp(np.eye(2), [1.0, 2.0, 3.0]), "q")


@pytest.mark.parametrize("value", [np.nan, np.inf, -0.1, 1.5, "0.5", None, True, 1j, [0.5]])
def test_restitution(value: object) -> None:
    refuses(lambda: iq.moreau(CRADLE, value), "eps")
    refuses(lambda: iq.Moreau(value), "eps")


@pytest.mark.parametrize("value", [np.nan, -0.1, 1.5, "0.5", None, 1j, [0.5, 0.5, 0.5]])
def test_local_coefficients(value: object) -> None:
    refuses(lambda: iq.newton(CRADLE, value), "e")
    refuses(lambda: iq.fremond(CRADLE, value), "E")


@pytest.mark.parametrize("tol", [np.nan, np.inf, -1.0, 0.0, 1.0, "1e-9", None, True])
def test_tolerance(tol: object) -> None:
    refuses(lambda: iq.moreau(CRADLE, 0.5, tol=tol), "tol")
    refuses(lambda: iq.sector_law(CRADLE, tol=tol), "tol")
    refuses(lambda: iq.solve_lcp(np.eye(2), [-1.0, 0.0], tol=tol), "tol")
    refuses(lambda: iq.moreau_batch(CRADLE, np.zeros((2, 3)), tol=tol), "tol")
    if tol is not None:  # None is contains' own default
        refuses(lambda: CRADLE.admissible_set().contains([0, 0, 1.0], tol=tol), "tol")


@pytest.mark.parametrize("backend", ["nope", None, 3, ["auto"], "qpsolvers:nope", "exact:x"])
def test_backend(backend: object) -> None:
    refuses(lambda: iq.moreau(CRADLE, 0.5, backend), "backend")
    refuses(lambda: iq.solve_lcp(np.eye(2), [-1.0, 0.0], backend), "backend")


@pytest.mark.parametrize("form", ["speed", None, 1, ["auto"]])
def test_form(form: object) -> None:
    refuses(lambda: iq.moreau(CRADLE, 0.5, form=form), "form")


def test_flags_and_counts() -> None:
    refuses(lambda: iq.chain([1.0, 1.0], [1.0, 0.0], left_wall="no"), "left_wall")
    refuses(lambda: iq.chain([1.0, 1.0], [1.0, 0.0], right_wall=1), "right_wall")
    refuses(lambda: iq.chain([1.0, -1.0], [1.0, 0.0]), "masses")
    refuses(lambda: iq.chain([1.0, 1j], [1.0, 0.0]), "masses")
    refuses(lambda: iq.newtons_cradle(3.0), "n_balls")
    refuses(lambda: iq.newtons_cradle("3"), "n_balls")
    refuses(lambda: iq.newtons_cradle(3, v=np.nan), "v")
    refuses(lambda: iq.newtons_cradle(3, v="1"), "v")
    refuses(lambda: iq.newtons_cradle(3, mass=0.0), "mass")
    refuses(lambda: iq.newtons_cradle(3, released=3), "released")
    refuses(lambda: iq.random_impact(3.5, 2), "n_dof")
    refuses(lambda: iq.random_impact(3, "2"), "n_contacts")
    refuses(lambda: iq.random_impact(3, 2, redundant=3), "redundant")
    refuses(lambda: iq.random_impact(3, 2, condition=0.5), "condition")


def test_wrong_objects() -> None:
    refuses(lambda: iq.moreau(None), "problem")
    refuses(lambda: iq.moreau("cradle"), "problem")
    refuses(lambda: iq.solve(CRADLE, "moreau"), "law")
    refuses(lambda: iq.solve(CRADLE, iq.Moreau), "law")
    refuses(lambda: iq.classify(None, [0, 0, 1.0]), "problem")
    refuses(lambda: iq.moreau_batch(CRADLE, [[1.0, 0.0], [0.0]]), "U_minus")
    refuses(lambda: iq.moreau_batch(CRADLE, np.zeros((2, 2))), "U_minus")
    refuses(lambda: iq.sector_law_batch(CRADLE, [[1j, 0, 0]]), "U_minus")
    refuses(lambda: iq.solve(CRADLE, iq.Fremond(np.eye(3))), "E")
    refuses(lambda: iq.solve(CRADLE, iq.Newton([1.0, 0.5, 0.5])), "e")


def test_complex_is_never_truncated() -> None:
    # numpy would keep the real part with a warning; impactqp refuses
    with pytest.raises(iq.InputError, match="complex"):
        iq.ImpactProblem(M3, W3, np.array([1 + 0j, 0, 0]))


@pytest.mark.parametrize("backend", ["exact", "qpsolvers:daqp", "qpsolvers:quadprog"])
def test_dense_backends_refuse_large_sparse_problems(backend: str) -> None:
    u = np.zeros(5000)
    u[0] = 1.0
    with pytest.raises(iq.BackendUnsuitableError, match="dense"):
        iq.moreau(iq.chain(np.ones(5000), u), 1.0, backend)


def test_tables_and_maps() -> None:
    refuses(lambda: iq.tables.reflection_law_table("a"), "masses")
    refuses(lambda: iq.tables.reflection_law_table([1.0, 1j, 1.0]), "masses")
    refuses(lambda: iq.tables.sector_law_table("3"), "n_balls")
    refuses(lambda: iq.tables.continuous_mass_ratios(None), "k")
    refuses(lambda: iq.verification.fremond_admissibility_map(CRADLE, None, [0.0]), "a_values")
    refuses(lambda: iq.verification.fremond_admissibility_map(CRADLE, [np.nan], [0.0]), "a_values")
    refuses(lambda: iq.verification.fremond_admissibility_map(CRADLE, [0.5], [0.0], samples="a"),
            "samples")
    refuses(lambda: iq.verification.fremond_admissibility_map(None, [0.5], [0.0]), "problem")
    refuses(lambda: iq.load_problem(None), "path")
