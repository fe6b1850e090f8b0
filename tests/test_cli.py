import subprocess
import sys

import impactqp.cli as cli
from impactqp.cli.demo import cradle_rows


def test_demo_rows():
    rows = cradle_rows()
    assert [r["case"] for r in rows] == ["Moreau eps=0", "Moreau eps=1", "observed cradle"]
    assert all(r["in_S"] and r["in_S_optimizer"] for r in rows)
    assert abs(rows[2]["alpha_deg"] - 30.0) < 1e-9


def test_demo_command(capsys):
    assert cli.main(["demo"]) == 0
    out = capsys.readouterr().out
    assert "observed cradle" in out and "30.00" in out and "FAILED" not in out


def test_bad_backend_exit_code(capsys):
    assert cli.main(["demo", "--backend", "nope"]) == 2
    assert "unknown backend" in capsys.readouterr().err


def test_module_entry_point():
    out = subprocess.run([sys.executable, "-m", "impactqp", "demo", "--balls", "4"],
                         capture_output=True, text=True, check=True).stdout
    assert "4 balls" in out
