import json
import sys

import numpy as np
import pytest

import impactqp as iq
from impactqp.io import files, save


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_round_trip_chain(tmp_path, suffix):
    p = iq.chain([1.0, 2.0, 3.5], [1.5, 0.25, -1e-7], left_wall=True)
    path = iq.save_problem(p, tmp_path / f"c{suffix}", law="newton", coefficients=[0.1, 0.2, 0.3],
                           u_plus=[0.1, 0.2, 0.3])
    f = iq.load_problem(path)
    assert f.path == path and f.law == "newton"
    assert f.problem.chain.left_wall and not f.problem.chain.right_wall
    np.testing.assert_array_equal(f.problem.chain.masses, [1.0, 2.0, 3.5])
    np.testing.assert_array_equal(f.problem.u_minus, p.u_minus)
    np.testing.assert_array_equal(f.problem.W, p.W)
    np.testing.assert_array_equal(f.coefficients, [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(f.u_plus, [0.1, 0.2, 0.3])


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_round_trip_dense_is_bit_exact(tmp_path, suffix):
    p = iq.random_impact(4, 3, seed=7)
    E = np.random.default_rng(0).random((3, 3))
    f = iq.load_problem(iq.save_problem(p, tmp_path / f"d{suffix}", law="fremond",
                                        coefficients=E))
    assert f.problem.chain is None and f.u_plus is None
    np.testing.assert_array_equal(f.problem.M, p.M)
    np.testing.assert_array_equal(f.problem.W, p.W)
    np.testing.assert_array_equal(f.problem.u_minus, p.u_minus)
    np.testing.assert_array_equal(f.coefficients, E)


def test_moreau_eps_and_bare_problem(tmp_path):
    p = iq.newtons_cradle()
    f = iq.load_problem(iq.save_problem(p, tmp_path / "m.toml", law="moreau", coefficients=0.5))
    assert f.coefficients == 0.5 and isinstance(f.coefficients, float)
    bare = iq.load_problem(iq.save_problem(p, tmp_path / "b.json"))
    assert bare.law is None and bare.coefficients is None and bare.u_plus is None


def test_scalar_newton_e_broadcasts(tmp_path):
    path = tmp_path / "n.json"
    path.write_text('{"masses": [1, 1], "u_minus": [1, 0], "law": "newton", "e": 1}')
    np.testing.assert_array_equal(iq.load_problem(path).coefficients, [1.0])


BAD = [
    ('[1, 2]', "top level"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "colour": 1}', "unknown key(s) ['colour']"),
    ('{"masses": [1, 1], "masses": [1, 1], "u_minus": [1, 0]}', "duplicate key 'masses'"),
    ('{"masses": [1, 1], "u_minus": [1, NaN]}', "NaN is not a finite number"),
    ('{"masses": [1, 1], "u_minus": [1, "0"]}', "u_minus[1] must be a number, got str"),
    ('{"masses": [1, true], "u_minus": [1, 0]}', "masses[1] must be a number, got bool"),
    ('{"masses": [1, 1], "u_minus": 3}', "u_minus must be a list"),
    ('{"masses": [1, 1], "u_minus": [1, 0, 0]}', "u_minus must have shape (2,)"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "left_wall": 1}', "left_wall must be true or false"),
    ('{"masses": [1, 1], "M": [[1]], "u_minus": [1, 0]}', "not both"),
    ('{"u_minus": [1, 0]}', "either a general problem"),
    ('{"masses": [1, 1]}', "missing key 'u_minus'"),
    ('{"left_wall": true, "u_minus": [1]}', "a chain needs 'masses'"),
    ('{"M": [[1, 0], [0, 1]], "u_minus": [1, 0]}', "missing ['W']"),
    ('{"M": [[1, 0], [0]], "W": [[1], [1]], "u_minus": [1, 0]}', "M is ragged"),
    ('{"M": [[1, 0], [0, 1]], "W": [[1, 2]], "u_minus": [1, 0]}', "W must have shape (n, m)"),
    ('{"M": [[1, 2], [2, 1]], "W": [[1], [1]], "u_minus": [1, 0]}', "positive definite"),
    ('{"M": [], "W": [[1], [1]], "u_minus": [1, 0]}', "M must be a non-empty list of rows"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "law": "magic"}', "law must be one of"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "law": "moreau", "e": 0.5}', "'e' does not fit"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "eps": 0.5}', "does not fit no law"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "law": "moreau", "eps": 1.5}', "eps must lie in"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "law": "fremond", "E": [[1, 0]]}', "E must be an"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "u_plus": [0]}', "u_plus must have shape (2,)"),
    ('{"masses": [1, 1], "u_minus": [1, 0], "version": 2}', "version must be 1"),
    ('{"masses": [1, 1], "u_minus": [1, 0]', "not valid JSON"),
]


@pytest.mark.parametrize("text, message", BAD)
def test_bad_json_files_name_the_field(tmp_path, text, message):
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(iq.errors.ProblemFileError) as info:
        iq.load_problem(path)
    assert message in str(info.value) and str(path) in str(info.value)
    assert isinstance(info.value, ValueError)


@pytest.mark.parametrize("text, message", [
    ('masses = [1, 1]\nu_minus = [1, 0]\nmasses = [2]\n', "not valid TOML"),
    ('masses = [1, 1]\nu_minus = [1, 0]\n[extra]\nx = 1\n', "unknown key(s) ['extra']"),
    ('masses = [1, 1]\nu_minus = [1, inf]\n', "u_minus[1] must be finite"),
])
def test_bad_toml_files(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(iq.errors.ProblemFileError) as info:
        iq.load_problem(path)
    assert message in str(info.value)


def test_limits_and_paths(tmp_path, monkeypatch):
    with pytest.raises(iq.errors.ProblemFileError, match="suffix '.yaml'"):
        iq.load_problem(tmp_path / "p.yaml")
    with pytest.raises(iq.errors.ProblemFileError, match="cannot read"):
        iq.load_problem(tmp_path / "missing.json")
    big = tmp_path / "big.json"
    big.write_text(json.dumps({"masses": [1.0] * 11, "u_minus": [0.0] * 11}))
    monkeypatch.setattr(files, "MAX_DOF", 10)
    with pytest.raises(iq.errors.ProblemFileError, match="limited to 10"):
        iq.load_problem(big)
    monkeypatch.setattr(files, "MAX_FILE_BYTES", 100)
    with pytest.raises(iq.errors.ProblemFileError, match="MB limit"):
        iq.load_problem(big)


def test_toml_without_tomllib_says_what_to_install(tmp_path, monkeypatch):
    path = iq.save_problem(iq.newtons_cradle(), tmp_path / "c.toml")
    monkeypatch.setitem(sys.modules, "tomllib", None)
    monkeypatch.setitem(sys.modules, "tomli", None)
    with pytest.raises(iq.errors.ProblemFileError, match="pip install tomli"):
        iq.load_problem(path)


def test_save_refuses_what_it_could_not_read(tmp_path):
    p = iq.newtons_cradle()
    with pytest.raises(iq.InputError, match="coefficients need a law"):
        iq.save_problem(p, tmp_path / "x.json", coefficients=0.5)
    with pytest.raises(iq.errors.ProblemFileError, match="eps must lie in"):
        iq.save_problem(p, tmp_path / "x.json", law="moreau", coefficients=2.0)
    assert not (tmp_path / "x.json").exists()


def test_toml_writer_round_trips_exactly():
    tomllib = files._toml_module()
    data = {"version": 1, "law": "sector", "left_wall": True,
            "M": [[1e-300, -2.5e17], [0.1, 1 / 3]]}
    text = save.to_toml(data)
    assert text.startswith('version = 1\nlaw = "sector"\nleft_wall = true\nM = [')
    back = tomllib.loads(text)
    assert back == data and all(isinstance(v, float) for row in back["M"] for v in row)


def test_every_law_named_in_files_is_the_registrys() -> None:
    """Files, the command line and the registry share one table of law names: every name
    builds its law (with coefficients where it takes them) and solves the cradle, or a sphere
    landing on two planes for a law of frictional contacts."""
    from impactqp.laws.catalogue import NAMED_LAWS, law_named

    cradle = iq.newtons_cradle(3)
    sphere = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.3])
    frictional = iq.ImpactProblem(sphere.M, np.hstack([sphere.structure.W] * 2), sphere.u_minus,
                                  contact_dim=2)
    coefficients = {"eps": 0.5, "e": [1.0, 0.5], "E": [[0.5, 0.0], [0.0, 0.5]],
                    "mu": [0.2, 0.4], "stiffness": 1e6, "exponent": 1.5}
    for name, law_class in NAMED_LAWS.items():
        keys = law_class.coefficient_keys
        given = tuple(coefficients[k] for k in keys)
        law = law_named(name, given if len(keys) > 1 else given[0] if keys else None)
        p = frictional if law_class.frictional else cradle
        assert type(law) is law_class and iq.solve(p, law).certificate.ok
        assert iq.solve(p, law_named(name, law.coefficients)).u_plus.tolist() == \
            iq.solve(p, law).u_plus.tolist()
        if law_class.needs_coefficients:
            with pytest.raises(iq.InputError, match="needs its coefficients"):
                law_named(name)
    with pytest.raises(iq.InputError, match="must be one of"):
        law_named("hertz")
    with pytest.raises(iq.InputError, match="takes no coefficients"):
        law_named("sector", 0.5)
