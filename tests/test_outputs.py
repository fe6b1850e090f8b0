"""Outputs go only to regular files: a FIFO, a device or a directory named as an output is
refused at once (a FIFO would block the writer forever), from Python and the command line."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import impactqp as iq
import impactqp.cli as cli

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes need POSIX")


@pytest.fixture
def fifo(tmp_path):
    def make(name: str) -> Path:
        path = tmp_path / name
        os.mkfifo(path)
        return path
    return make


def test_python_writers_refuse_a_fifo(fifo, tmp_path):
    tr = iq.simulate(iq.simulation.bouncing_ball(), iq.Newton(0.9), 0.5, h=0.01)
    with pytest.raises(iq.InputError, match="not a regular file"):
        tr.save(fifo("run.npz"))
    with pytest.raises(iq.InputError, match="not a regular file"):
        iq.save_problem(iq.newtons_cradle(3), fifo("p.toml"))
    (tmp_path / "dir.npz").mkdir()
    with pytest.raises(iq.InputError, match="not a regular file"):
        tr.save(tmp_path / "dir.npz")  # a directory
    pytest.importorskip("matplotlib")
    with pytest.raises(iq.InputError, match="not a regular file"):
        tr.plot(path=fifo("q.png"))
    assert tr.save(tmp_path / "new.npz").stat().st_size > 0  # a new regular file is fine


def test_the_command_line_refuses_a_fifo_before_running(fifo, capsys):
    assert cli.main(["simulate", str(EXAMPLES / "bouncing_ball.toml"), "--quiet",
                     "--out", str(fifo("run.npz"))]) == 2
    assert "not a regular file" in capsys.readouterr().err
    pytest.importorskip("matplotlib")
    assert cli.main(["plot", "cradle", "--out", str(fifo("c.png")), "--force"]) == 2
    assert "not a regular file" in capsys.readouterr().err


def test_a_simulation_file_with_a_list_for_t_end_is_named(tmp_path, capsys):
    path = tmp_path / "run.toml"
    path.write_text('[system]\nkind = "bouncing_ball"\n[law]\nname = "newton"\ne = 0.9\n'
                    "[simulation]\nt_end = [1.0]\n")
    assert cli.main(["simulate", str(path), "--quiet"]) == 2
    assert "t_end must be one real number" in capsys.readouterr().err
    path.write_text('[system]\nkind = "bouncing_ball"\n[law]\nname = "newton"\ne = 0.9\n'
                    "[simulation]\nh = 0.01\n")
    assert cli.main(["simulate", str(path), "--quiet"]) == 2
    assert "needs t_end" in capsys.readouterr().err
