"""Every certificate impactqp returns is one type, :class:`impactqp.Certificate`
(docs/theory.md §8): the impact laws', Coulomb's, solve_friction's, a batch's, LZB's, the
sector and reflection tables', and a frictional simulation step's — each with its residuals
readable by name, the ones its law declares."""

from __future__ import annotations

import numpy as np
import pytest

import impactqp as iq
from impactqp.base.checks import BatchCertificate, NamedChecks, ResidualChecks
from impactqp.laws.lzb import LZBCertificate
from impactqp.model.friction import FrictionCertificate, certify_friction
from impactqp.simulation.builders import rolling_sphere
from impactqp.simulation.friction_step import StepMembership
from impactqp.tables.certificate import SectorCertificate, TableCertificate, table_report

U = np.array([1.0, 0.2, -0.5])
"""u⁻ of a three-ball chain: the first two collide."""

LAWS = {
    "moreau": (iq.Moreau(0.5), lambda: iq.chain(np.ones(3), U)),
    "newton": (iq.Newton(0.5), lambda: iq.chain(np.ones(3), U)),
    "fremond": (iq.Fremond(0.5 * np.eye(2)), lambda: iq.chain(np.ones(3), U)),
    "sector": (iq.SectorLaw(), lambda: iq.chain(np.ones(3), U)),
    "reflection": (iq.ReflectionLaw(), lambda: iq.chain(np.ones(3), U)),
    "lzb": (iq.LZB(1e5), lambda: iq.chain(np.ones(3), U)),
    "coulomb": (iq.Coulomb(0.3), lambda: iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0])),
}


def test_the_old_names_are_the_one_type() -> None:
    for alias in (ResidualChecks, NamedChecks, LZBCertificate, FrictionCertificate,
                  StepMembership, TableCertificate, SectorCertificate,
                  iq.results.SectorLawCertificate, iq.results.ResidualChecks):
        assert alias is iq.results.Certificate
    assert issubclass(BatchCertificate, iq.results.Certificate)


@pytest.mark.parametrize("name", LAWS)
def test_every_law_returns_a_certificate_with_its_declared_residuals(name: str) -> None:
    law, problem = LAWS[name]
    r = iq.solve(problem(), law)
    cert = r.certificate
    assert isinstance(cert, iq.results.Certificate) and cert.ok and r.success
    assert set(cert.values) <= set(type(law).residual_names), (name, cert.values)
    for k, v in cert.values.items():  # attribute access for the names it holds
        assert getattr(cert, k) == v
    # a declared residual it has not got reads as None; an undeclared name is an error
    for k in set(type(law).residual_names) - set(cert.values):
        assert getattr(cert, k) is None
    with pytest.raises(AttributeError, match="no attribute 'not_a_residual'"):
        cert.not_a_residual  # noqa: B018


def test_only_moreau_declares_the_duality_gap() -> None:
    chain = iq.chain(np.ones(3), U)
    assert iq.solve(chain, iq.Moreau(0.5)).certificate.duality_gap is not None
    newton = iq.solve(chain, iq.Newton(0.5)).certificate
    assert "duality_gap" not in newton.values and newton.duality_gap is None


def test_lzb_judges_the_integration_against_its_own_tolerance() -> None:
    r = iq.solve(iq.chain(np.ones(3), U), iq.LZB(1e5))
    cert = r.certificate
    assert cert.record is not None and cert.record.steps > 0
    itol = cert.integration_tol
    assert itol >= cert.tol
    assert {cert.tol_of(k) for k in ("kinematic", "energy_balance", "potential_left")} == {itol}
    assert cert.tol_of("momentum") == cert.tol_of("impulse_sign") == cert.tol


def test_solve_friction_reports_beside_its_verdict() -> None:
    p = iq.FrictionContactProblem(np.eye(3), [-1.0, 0.5, 0.0], 0.3)
    r = iq.solve_friction(p)
    cert = r.certificate
    assert isinstance(cert, iq.results.Certificate) and cert.ok
    assert cert.error == cert.natural_map == r.error
    assert set(cert.reported) == {"siconos_error", "penetration"}
    assert "reported: siconos_error=" in cert.summary()
    # a reported figure does not enter the verdict: a wrong r fails by its residuals
    bad = certify_friction(p, np.array([2.0, 0.0, 0.0]))
    assert not bad.ok and bad.worst[1] > 1e-3


def test_a_batch_certificate_has_a_verdict_per_row() -> None:
    p = iq.chain(np.ones(3), U)
    rows = np.array([U, -U, 2 * U])
    b = iq.solve_batch(p, iq.Newton(0.5), rows)
    cert = b.certificate
    assert isinstance(cert, iq.results.Certificate) and isinstance(cert, BatchCertificate)
    assert cert.ok.tolist() == [True] * 3 and bool(cert)
    # per row, like the single impacts
    for u, ok in zip(rows, cert.ok, strict=True):
        single = iq.solve(p.with_u_minus(u), iq.Newton(0.5)).certificate
        assert single.ok == ok
    bad = BatchCertificate({"momentum": [0.0, 1.0, np.nan]}, 1e-9)
    assert bad.ok.tolist() == [True, False, False] and not bad
    assert bad.worst[0] == "momentum" and bad.worst[1] == np.inf


@pytest.mark.parametrize("table", [lambda: iq.tables.sector_law_table(3),
                                   lambda: iq.tables.reflection_law_table(np.ones(3))])
def test_the_tables_certificates_count_failing_cones(table) -> None:
    t = table()
    cert = t.certificate
    assert isinstance(cert, iq.results.Certificate)
    assert cert.ok and cert.maximal_monotone and cert.admissible
    assert all(v == 0 for v in cert.values.values())
    assert cert.kinematic.passed and cert.continuity.passed  # the checks, as extras
    assert "maximal monotone: True" in table_report(cert)


def test_a_broken_table_fails_its_certificate() -> None:
    from dataclasses import replace

    t = iq.tables.sector_law_table(3)
    cones = [replace(c, Q=1.1 * c.Q) for c in t.cones]  # expands every piece
    cert = iq.tables.SectorTable(cones=cones, G=t.G, W=t.W, n_balls=3).certificate
    assert not cert.ok and not cert.maximal_monotone
    assert cert.expanding_cones == len(cones) and cert.discontinuous_pairs == 0
    assert not cert.non_expansive.passed and cert.continuity.passed


def test_a_frictional_simulation_step_has_certificates() -> None:
    system = rolling_sphere(radius=0.1, velocity=1.0, gap=-1e-9)
    tr = iq.simulate(system, iq.Coulomb(0.3), 0.05)
    assert tr.events
    for ev in tr.events[:5]:
        assert isinstance(ev.certificate, iq.results.Certificate) and ev.certificate.ok
        member = ev.admissible
        assert isinstance(member, iq.results.Certificate) and member.ok
        assert set(member.values) == {"kinetic", "kinematic", "energetic"}
