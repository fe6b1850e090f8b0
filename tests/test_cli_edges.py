"""The command line's edges: ``solve --law lzb``, errors in the command line's own words,
``simulate --json`` listing impacts (not every step of a resting contact), progress on a
terminal only, a closed output pipe ending quietly, and a frictional run's summary saying why
certified steps leave S."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
from impactqp.base.checks import Certificate
from impactqp.cli.commands.simulate import impact_times
from impactqp.cli.main import main
from impactqp.cli.progress import on_terminal, progress
from impactqp.simulation import box_on_floor

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
CHAIN = """version = 1
masses = [1.0, 1.0, 1.0]
u_minus = [1.0, 0.0, 0.0]
"""


def _run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    status = main(argv)
    out = capsys.readouterr()
    return status, out.out, out.err


def test_solve_law_lzb_matches_python(tmp_path: Path, capsys) -> None:
    path = tmp_path / "chain.toml"
    path.write_text(CHAIN)
    status, out, _ = _run(["solve", str(path), "--law", "lzb", "--stiffness", "1e6",
                           "--exponent", "1", "--e", "0.9", "--json"], capsys)
    assert status == 0
    report = json.loads(out)
    expected = iq.solve(iq.load_problem(path).problem, iq.LZB(1e6, 1.0, 0.9))
    assert report["law"] == "lzb" and report["backend"] == "lzb"
    np.testing.assert_allclose(report["u_plus"], expected.u_plus, rtol=0, atol=1e-12)
    status, out, _ = _run(["solve", str(path), "--law", "lzb", "--stiffness", "1e6"], capsys)
    assert status == 0 and "law lzb, K = (+1e+06, +1e+06), η = (+1.5, +1.5), e = (+1, +1)" in out
    # from the file, with the LZB model's keys
    path.write_text(CHAIN + 'law = "lzb"\nstiffness = [1e6, 2e6]\nexponent = 1.5\n')
    status, out, _ = _run(["solve", str(path)], capsys)
    assert status == 0 and "law lzb, K = (+1e+06, +2e+06)" in out
    path.write_text(CHAIN)
    status, _, err = _run(["solve", str(path), "--law", "lzb"], capsys)
    assert status == 2 and "pass --stiffness" in err


PYTHON_ADVICE = ("iq.", "()", "normal_problem", "Coulomb(", "Newton(")


@pytest.mark.parametrize("argv, words", [
    (["solve", "examples/sphere_on_plane.toml", "--law", "moreau"], "--law coulomb --mu"),
    (["solve", "examples/cradle.toml", "--law", "coulomb", "--mu", "0.3"], "--law newton"),
    (["solve", "examples/cradle.toml", "--law", "sector", "--backend", "clarabel"],
     "drop --backend clarabel"),
    (["plot", "S", "examples/sphere_on_plane.toml", "--out", "{tmp}/s.png"], "contact_dim = 1"),
])
def test_errors_speak_in_flags(argv, words, tmp_path: Path, capsys, monkeypatch) -> None:
    monkeypatch.chdir(ROOT)
    status, _, err = _run([a.replace("{tmp}", str(tmp_path)) for a in argv], capsys)
    assert status == 2 and words in err
    assert not [advice for advice in PYTHON_ADVICE if advice in err], err


def test_simulate_json_lists_impacts_not_resting_steps(capsys) -> None:
    status, out, _ = _run(["simulate", str(EXAMPLES / "block_on_incline.toml"), "--json"],
                          capsys)
    report = json.loads(out)
    assert status == 0 and report["events"] == 300  # a step with the contact closed, each
    assert report["impact_times"] == []  # pushed along the plane: never an impact
    # a ball dropped on the ground by time-stepping: its bounces, at the event-driven times
    argv = ["simulate", str(EXAMPLES / "bouncing_ball.toml"), "--json"]
    event = json.loads(_run(argv, capsys)[1])["impact_times"]
    stepped = json.loads(_run([*argv, "--scheme", "moreau-jean", "--h", "1e-3"], capsys)[1])
    assert stepped["events"] > 10 * len(stepped["impact_times"]) > 100  # resting at the end
    np.testing.assert_allclose(stepped["impact_times"][:4], event[:4], atol=5e-3)


def test_impacts_of_time_stepping_by_hand() -> None:
    """impact_times against the definition, record by record: a step is an impact when a
    closed contact approached at its start and took a positive normal impulse."""
    system = iq.simulation.bouncing_ball(q0=0.3)
    run = iq.simulate(system, iq.Newton(0.5), 1.0, h=1e-3)
    gamma = np.asarray(system.H.T @ run.v.T).ravel()
    expected = [float(run.t[i]) for i in range(1, run.t.size)
                if gamma[i - 1] < -1e-6 * np.abs(gamma).max() and run.impulses[i, 0] > 0]
    assert 3 <= len(expected) < len(run.events)
    assert impact_times(run) == expected


def test_progress_only_on_a_terminal(monkeypatch) -> None:
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    pipe, tty = io.StringIO(), Terminal()
    assert not on_terminal(pipe) and on_terminal(tty)
    for stream in (pipe, tty):
        monkeypatch.setattr(sys, "stderr", stream)
        with progress("slow step", after=0.01, every=0.02):
            import time
            time.sleep(0.1)
    assert pipe.getvalue() == "" and "slow step" in tty.getvalue()


def test_simulate_bar_only_on_a_terminal(monkeypatch) -> None:
    from impactqp.cli.commands import simulate as command

    made, Bar = [], command._Bar
    monkeypatch.setattr(command, "_Bar", lambda t0, t_end, enabled: made.append(enabled)
                        or Bar(t0, t_end, False))
    for tty in (False, True):
        monkeypatch.setattr(command, "on_terminal", lambda tty=tty: tty)
        assert main(["simulate", str(EXAMPLES / "bouncing_ball.toml"), "--t-end", "0.1",
                     "--quiet" if tty else "--json"]) == 0
        assert main(["simulate", str(EXAMPLES / "bouncing_ball.toml"), "--t-end", "0.1"]) == 0
    assert made == [False, False, False, True]


def test_closed_pipe_ends_quietly(tmp_path: Path) -> None:
    """The reader closes the pipe before the command writes: exit 0, nothing on stderr."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "impactqp", "simulate",
                             str(EXAMPLES / "bouncing_ball.toml"), "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env)
    proc.stdout.close()
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=240) == 0
    assert "error" not in err and "Broken pipe" not in err and "Exception" not in err, err


def test_summary_says_why_certified_steps_leave_S() -> None:
    """A box dropped on the floor with Newton's restitution and Coulomb friction: steps keep
    a separating corner closed; the summary counts them as the verdicts do."""
    run = iq.simulate(box_on_floor(dim=2, velocity=2.0, gap=0.05), iq.Coulomb(0.3, 0.5), 1.0,
                      h=1e-3)
    verdicts = [e.admissible for e in run.events]
    by_hand = {name: sum(1 for v in verdicts if v.values[name] > v.tol)
               for name in ("kinetic", "kinematic", "energetic")}
    outside = int((~run.admissible()).sum())
    assert run.certified and outside > 0
    assert run.outside_S() == {k: n for k, n in by_hand.items() if n}
    text = run.summary()
    assert f"u⁺ ∈ S: {len(verdicts) - outside} of {len(verdicts)}" in text
    assert f"kinematic residual above tolerance: {by_hand['kinematic']} steps" in text
    assert "docs/theory.md §16, §17" in text and "Coulomb friction" in text
    # energy rising is named and counted the same way (a verdict failing it, made by hand)
    from impactqp.simulation import trajectory

    failing = Certificate({"kinetic": 0.0, "kinematic": 0.0, "energetic": 0.2}, 1e-9)
    assert trajectory._failed(failing) == ["energetic"]
    assert trajectory.LEAVING_S["energetic"] == "energy rising"


def test_summary_is_silent_when_every_step_is_in_S() -> None:
    run = iq.simulate(box_on_floor(dim=2, velocity=2.0, gap=-1e-9), iq.Coulomb(0.3), 0.2,
                      h=1e-3)
    assert run.admissible().all() and run.outside_S() == {}
    assert "outside S" not in run.summary()
