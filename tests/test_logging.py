"""impactqp's log: backend attempts and certificate verdicts at DEBUG, refusals and fallbacks
at INFO, under the "impactqp" logger; verbose= and the CLI's -v print it on stderr."""

from __future__ import annotations

import logging

import numpy as np
import pytest

import impactqp as iq
import impactqp.cli as cli
from impactqp.laws import small


def test_attempts_and_verdicts_are_logged_at_debug(caplog):
    with caplog.at_level(logging.DEBUG, logger="impactqp"):
        r = iq.solve(iq.newtons_cradle(3), iq.Moreau(1.0), backend="clarabel")
    messages = [rec.getMessage() for rec in caplog.records]
    assert any(m.startswith("clarabel") and "certified" in m for m in messages)
    assert any(m.startswith("certificate ok") for m in messages)
    assert all(rec.name.startswith("impactqp.") for rec in caplog.records)
    assert r.attempts[-1] in messages  # the result's attempts are the log's lines


def test_a_declined_compiled_path_is_logged_at_info(caplog, monkeypatch):
    monkeypatch.setattr(small, "solve_small", lambda *args: None)
    with caplog.at_level(logging.INFO, logger="impactqp"):
        r = iq.moreau(iq.newtons_cradle(3), 1.0)
    assert r.certificate.ok
    infos = [rec for rec in caplog.records if rec.levelno == logging.INFO]
    assert any("compiled path declined" in rec.getMessage() for rec in infos)
    assert not any(rec.levelno == logging.DEBUG for rec in caplog.records)


def test_refusals_by_size_are_logged_at_info(caplog):
    p = iq.chain(np.ones(60_000), np.r_[1.0, np.zeros(59_999)])
    with caplog.at_level(logging.INFO, logger="impactqp"), \
            pytest.raises(iq.BackendUnsuitableError):
        iq.moreau(p, 0.0, backend="osqp")
    assert any("converges too slowly" in rec.getMessage() for rec in caplog.records)


def test_verbose_prints_on_stderr_for_one_call_only(capsys):
    root = logging.getLogger("impactqp")
    level, handlers = root.level, list(root.handlers)
    iq.solve(iq.newtons_cradle(3), iq.Moreau(1.0), backend="clarabel", verbose=2)
    err = capsys.readouterr().err
    assert "impactqp: DEBUG" in err and "certified" in err
    assert root.level == level and root.handlers == handlers
    iq.solve(iq.newtons_cradle(3), iq.Moreau(1.0), backend="clarabel")
    assert capsys.readouterr().err == ""
    iq.solve(iq.newtons_cradle(3), iq.Moreau(1.0), backend="clarabel", verbose=True)
    assert "DEBUG" not in capsys.readouterr().err  # True: INFO and above only
    with pytest.raises(iq.InputError, match="verbose"):
        iq.solve(iq.newtons_cradle(3), iq.Moreau(1.0), verbose="loud")


def test_verify_law_and_the_command_line_take_verbosity(tmp_path, capsys):
    iq.verify_law(iq.SectorLaw(), iq.newtons_cradle(3), samples=4, verbose=2)
    assert "impactqp: DEBUG" in capsys.readouterr().err
    path = tmp_path / "p.toml"
    path.write_text("M = [[1, 0], [0, 1]]\nW = [[-1], [1]]\nu_minus = [1, 0]\n")
    assert cli.main(["-vv", "solve", str(path), "--backend", "clarabel"]) == 0
    assert "impactqp: DEBUG impactqp.qp.certified: clarabel" in capsys.readouterr().err
    assert cli.main(["solve", str(path), "--backend", "clarabel"]) == 0
    assert capsys.readouterr().err == ""
