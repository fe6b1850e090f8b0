"""The shared verdict (impactqp/base/checks.py) judged at its edge, written to kill the
mutants benchmarks/mutation.py makes of it: a residual exactly at the tolerance passes, one
just above fails, a non-finite one fails, and the worst residual is the largest."""

from __future__ import annotations

import math

import numpy as np
import pytest

import impactqp as iq
from impactqp.base.checks import DEFAULT_TOL, FRICTION_TOL, UNIT_RANGE, NamedChecks

TOL = 1e-9


@pytest.mark.parametrize("factor, ok", [(0.0, True), (0.5, True), (1.0, True),
                                        (1.0 + 1e-12, False), (2.0, False)])
def test_verdict_at_its_edge(factor: float, ok: bool) -> None:
    # ≤ tol passes, including equality; anything above fails, however close
    checks = NamedChecks({"a": 0.1 * TOL, "b": factor * TOL}, TOL)
    assert checks.ok is ok
    assert bool(checks) is ok
    assert checks.summary().startswith("ok" if ok else "FAILED")


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_residual_that_cannot_be_evaluated_fails(bad: float) -> None:
    checks = NamedChecks({"a": 0.0, "b": bad}, TOL)
    assert not checks.ok
    assert checks.worst[0] == "b"


def test_a_negative_residual_is_within_tolerance() -> None:
    # residuals are magnitudes; a finite value below tol passes whatever its sign
    assert NamedChecks({"a": -1.0}, TOL).ok


def test_every_residual_counts() -> None:
    for k in range(3):
        values = dict.fromkeys("xyz", 0.0)
        values["xyz"[k]] = 3 * TOL
        assert not NamedChecks(values, TOL).ok


def test_worst_is_the_largest_and_none_when_empty() -> None:
    values = {"a": 3e-12, "b": 7e-10, "c": 1e-11}
    assert NamedChecks(values, TOL).worst == ("b", 7e-10)
    assert NamedChecks({"a": 2.0, "b": math.nan, "c": 5.0}, TOL).worst[0] == "b"
    empty = NamedChecks({}, TOL)
    assert empty.worst == ("none", 0.0)
    assert empty.ok


def test_summary_names_every_residual_and_the_tolerance() -> None:
    checks = NamedChecks({"gap": 2.5e-3, "energy": 1.25e-12}, 1e-6)
    assert checks.summary() == "FAILED (tol 1e-06): gap=2.5e-03, energy=1.2e-12"


def test_default_tolerance_rejects_a_visible_error_and_accepts_rounding() -> None:
    # the certificates' default is a dimensionless tolerance near 1e-9: rounding of a few ulps
    # of order-one numbers passes, an error of a millionth does not
    assert NamedChecks({"r": 1e-6}, DEFAULT_TOL).ok is False
    assert NamedChecks({"r": 50 * np.finfo(float).eps}, DEFAULT_TOL).ok is True
    assert iq.moreau(iq.newtons_cradle(3), 1.0).certificate.tol == DEFAULT_TOL


def test_friction_default_tolerance_is_the_accuracy_fclib_asks_for() -> None:
    # ABH ≤ 1e-8: an answer off by 1.5e-8 fails the default, one off by 0.5e-8 passes
    assert NamedChecks({"natural_map": 1.5e-8}, FRICTION_TOL).ok is False
    assert NamedChecks({"natural_map": 0.5e-8}, FRICTION_TOL).ok is True
    problem = iq.FrictionContactProblem(np.eye(3), np.array([-1.0, 0.5, 0.0]), 0.3)
    assert iq.solve_friction(problem).certificate.tol == FRICTION_TOL


@pytest.mark.parametrize("scale", [1e-90, 1.0, 1e90])
def test_unit_range_holds_the_velocities_worked_with_as_given(scale: float) -> None:
    # the range spans order one and every scale whose squares stay far inside the float range
    low, high = UNIT_RANGE
    assert low <= scale <= high
    assert 0.0 < low < 1.0 < high
    assert high ** 2 < np.finfo(float).max and low ** 2 > np.finfo(float).tiny


@pytest.mark.parametrize("factor, ok", [(0.5, True), (1.0, True), (2.0, False)])
def test_a_residual_with_its_own_tolerance_is_judged_by_it(factor: float, ok: bool) -> None:
    # LZB's integration-decided residuals: their own tolerance, the others keep ``tol``
    own = 1e3 * TOL
    cert = iq.results.Certificate({"exact": 0.5 * TOL, "integrated": factor * own}, TOL,
                          tols={"integrated": own})
    assert cert.ok is ok and cert.tol_of("integrated") == own and cert.tol_of("exact") == TOL
    assert not iq.results.Certificate({"exact": 2 * TOL}, TOL, tols={"integrated": own}).ok
    assert f"integrated {own:.0e}" in cert.summary()


def test_reported_figures_and_extras_are_shown_not_judged() -> None:
    cert = iq.results.Certificate({"a": 0.5 * TOL}, TOL, reported={"siconos": 1.0},
                          extras={"record": "r"}, names=("a", "b"))
    assert cert.ok and cert.worst == ("a", 0.5 * TOL)
    assert cert.summary() == "ok (tol 1e-09): a=5.0e-10; reported: siconos=1.0e+00"
    assert cert.a == 0.5 * TOL and cert.siconos == 1.0 and cert.record == "r"
    assert cert.b is None  # declared, not held
    with pytest.raises(AttributeError):
        cert.c  # noqa: B018


def test_the_velocity_error_bound_is_the_root_of_twice_the_gap() -> None:
    assert iq.results.Certificate({"duality_gap": 8e-12}, TOL).velocity_error_bound == \
        pytest.approx(4e-6, rel=1e-12)
    assert iq.results.Certificate({"momentum": 0.0}, TOL).velocity_error_bound is None


def test_a_batch_verdict_per_row_at_its_edge() -> None:
    from impactqp.base.checks import BatchCertificate

    cert = BatchCertificate({"a": [0.5 * TOL, TOL, 2 * TOL, math.nan],
                             "b": [0.0, 0.0, 0.0, 0.0]}, TOL)
    assert cert.ok.tolist() == [True, True, False, False] and not cert
    assert cert.worst == ("a", math.inf)
    assert bool(BatchCertificate({"a": [0.0, TOL]}, TOL))
    empty = BatchCertificate({"a": []}, TOL)
    assert empty.worst == ("none", 0.0) and empty.ok.tolist() == []


def test_a_certificate_takes_its_residuals_by_name_and_its_figures_by_keyword_only() -> None:
    """values and tol may be named; reported, extras, tols and names are keyword-only (a
    positional third argument is not silently taken for the reported figures)."""
    cert = iq.results.Certificate(values={"a": 0.5 * TOL}, tol=TOL)
    assert cert.ok and cert.residuals == {"a": 0.5 * TOL}
    with pytest.raises(TypeError):
        iq.results.Certificate({"a": 0.5 * TOL}, TOL, {"b": 1.0})
