"""Numbers beyond the floats on the command line end in a named error (exit 2, one line that
says which range was left), never in a bare OverflowError or a traceback."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
import impactqp.cli as cli
from impactqp.cli import demo
from impactqp.cli.main import out_of_range


@pytest.mark.parametrize("v, word", [("1e308", "overflow"), ("1e155", "overflow"),
                                     ("1e-320", "underflow"), ("1e-200", "underflow")])
def test_demo_out_of_range_is_named(capsys, v: str, word: str) -> None:
    assert cli.main(["demo", "--v", v]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "outside the demo's range" in captured.err and word in captured.err
    with pytest.raises(iq.OutOfRangeError):
        demo.cradle_rows(v=float(v))


def test_demo_at_the_ends_of_its_range_is_the_unit_table_scaled(capsys) -> None:
    unit = demo.cradle_rows(v=1.0)
    for v in demo.SPEEDS:
        rows = demo.cradle_rows(v=v)
        for row, one in zip(rows, unit, strict=True):
            np.testing.assert_allclose(row["u_plus"], v * one["u_plus"], rtol=1e-12,
                                       atol=1e-12 * v)
            np.testing.assert_allclose(row["impulses"], v * one["impulses"], rtol=1e-12,
                                       atol=1e-12 * v)
            assert row["energy_before"] == pytest.approx(v * v * one["energy_before"])
            assert row["in_S"] and row["alpha_deg"] == pytest.approx(one["alpha_deg"])
        assert cli.main(["demo", "--v", repr(v)]) == 0
        out = capsys.readouterr().out
        assert f"{v / 3:+.3e}" in out and len(max(out.splitlines(), key=len)) < 200


def test_the_command_line_names_an_overflow(capsys, monkeypatch) -> None:
    def overflow(**kwargs: object) -> None:
        return 10.0 ** 400  # what float arithmetic in Python raises beyond the range

    monkeypatch.setattr(demo, "cradle_rows", overflow)
    assert cli.main(["demo"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("impactqp: error: demo: a number left the range of floats")
    assert "OverflowError" not in err and len(err.strip().splitlines()) == 1
    assert isinstance(out_of_range("solve", OverflowError("x")), iq.OutOfRangeError)


@pytest.mark.parametrize("command", [["solve"], ["verify", "--u-plus", "1e308,0,1e308"]])
def test_huge_problem_files_end_in_a_result_or_a_named_error(tmp_path: Path,
                                                              command: list[str]) -> None:
    path = iq.save_problem(iq.newtons_cradle(3, 1e300 if command == ["solve"] else 1.0),
                           tmp_path / "big.toml")
    out = subprocess.run([sys.executable, "-m", "impactqp", command[0], str(path),
                          *command[1:]], capture_output=True, text=True, timeout=120)
    assert "Traceback" not in out.stderr and "OverflowError" not in out.stderr
    if out.returncode == 2:  # one named error: the report's energies (|v|² / 2) beyond the
        # floats, or S's cone program refusing a candidate at 1e308 by name
        assert len(out.stderr.strip().splitlines()) == 1
        assert "left the range of floats" in out.stderr or \
            "no backend certified the cone program" in out.stderr, out.stderr
    else:
        assert out.returncode in (0, 1)
        assert not re.search(r"(?<![a-z])[+-]?(inf|nan)(?![a-z])", out.stdout), out.stdout
