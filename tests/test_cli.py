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


def test_demo_refuses_a_ball_that_moves_away(capsys):
    for v in ("-1", "0"):
        assert cli.main(["demo", "--v", v]) == 2
        captured = capsys.readouterr()
        assert "v must be positive" in captured.err and "nan" not in captured.out


def test_solve_applies_the_python_checks_to_a_chain_given_by_its_matrices(tmp_path, capsys):
    """A problem file with M = I and a chain's W is a chain: the sector law applies, and a
    backend it cannot use is refused as iq.solve refuses it, in the command line's words."""
    import numpy as np

    import impactqp as iq
    from impactqp.model.builders import chain_directions

    path = tmp_path / "chain.toml"
    path.write_text("M = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n"
                    "W = [[-1, 0], [1, -1], [0, 1]]\nu_minus = [1, 0, 0]\n")
    assert cli.main(["solve", str(path), "--law", "sector"]) == 0
    assert "(+0, +0, +1)" in capsys.readouterr().out
    assert cli.main(["solve", str(path), "--law", "sector", "--backend", "kernel"]) == 2
    err = capsys.readouterr().err
    problem = iq.ImpactProblem(np.eye(3), chain_directions(3), [1.0, 0, 0])
    try:
        iq.solve(problem, iq.SectorLaw(), backend="kernel")
    except iq.ImpactError as exc:
        assert "evaluated in closed form" in str(exc)
        assert "--law sector is evaluated in closed form: drop --backend kernel" in err
    else:
        raise AssertionError("iq.solve accepted a backend the sector law cannot use")
