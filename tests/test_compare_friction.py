"""Every friction method on the user's own frictional contact problem (issue 27):
``iq.compare_backends(problem)`` on a FrictionContactProblem and ``impactqp bench`` on FCLib
and Siconos files; each certified answer checked again by an independent recomputation, and
every timed call made with its kernels compiled, never run as Python."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
from impactqp.cli.main import main
from impactqp.kernels import first_calls
from impactqp.laws.friction import FRICTION_BACKENDS
from impactqp.model.friction import certify_friction
from impactqp.verification import bench

DATA = Path(__file__).resolve().parent / "data" / "fclib"
SICONOS_1C = DATA / "FrictionContact3D_1c.dat"
LMGC = DATA / "LMGC_GlobalFrictionContactProblem00046.hdf5"


def test_every_friction_method_compared_and_each_answer_checked_apart() -> None:
    problem = iq.load_fclib(LMGC)
    table = iq.compare_backends(problem, repeats=2)
    assert table.law is None and table.tol == 1e-8
    assert [r.backend for r in table.runs] == list(FRICTION_BACKENDS)
    assert len(table.certified) >= 5 and table.best is not None
    best = table[table.best]
    assert best.error == 0.0 and best.margin == min(r.margin for r in table.certified)
    W = problem.dense_W()
    for run in table.certified:
        r = run.result.r
        u = W @ r + problem.q  # the velocity recomputed from r, apart from the solver
        assert certify_friction(problem, r, u).ok, run
        own = np.linalg.norm(u - (W @ best.result.r + problem.q)) / np.linalg.norm(problem.q)
        assert abs(own - run.error) <= 1e-12 + 1e-9 * own, run
        assert len(run.times) == 2 and run.time == pytest.approx(np.median(run.times))
    text = str(table)
    assert text.startswith("Coulomb friction (W, q, μ) on 9 contacts in 3-D")
    assert "several solutions" in text


def test_a_method_named_wrongly_is_a_refused_row_and_a_law_is_refused() -> None:
    problem = iq.load_fclib(SICONOS_1C)
    table = iq.compare_backends(problem, backends=["kernel", "exact", "nosuch"], repeats=1)
    assert table["kernel"].certified
    assert table["exact"].verdict == "refused" and "frictional" in table["exact"].reason
    assert table["nosuch"].verdict == "refused" and "unknown" in table["nosuch"].reason
    with pytest.raises(iq.InputError, match="carries its law"):
        iq.compare_backends(problem, iq.Moreau(0.5))
    with pytest.raises(iq.InputError, match="backends="):
        iq.compare_backends(problem, ["auto", "nsgs"])  # backends given in the law's place
    with pytest.raises(iq.InputError, match="tol"):
        iq.compare_backends(problem, backends=["kernel"], tol=2.0)
    with pytest.raises(iq.InputError, match="needs its law"):
        iq.compare_backends(iq.newtons_cradle(3))


@pytest.mark.parametrize("solver", ["solve_friction", "solve"])
def test_every_call_runs_compiled_kernels(monkeypatch: pytest.MonkeyPatch, solver: str) -> None:
    """A fresh process runs its first small calls as Python (kernels.first_calls); the
    comparison must compile them on its untimed calls instead, or it would time Python."""
    seen: list[bool] = []
    real = getattr(bench, solver)

    def spy(*args, **kwargs):
        seen.append(first_calls._state["compiling"] > 0)
        return real(*args, **kwargs)
    monkeypatch.setattr(bench, solver, spy)
    if solver == "solve":
        iq.compare_backends(iq.newtons_cradle(3), iq.Moreau(1.0), ["exact"], repeats=3)
    else:
        iq.compare_backends(iq.load_fclib(SICONOS_1C), backends=["kernel"], repeats=3)
    assert seen == [True] * (bench.WARM_UP + 3)


def test_bench_reads_fclib_and_siconos_files(capsys: pytest.CaptureFixture) -> None:
    assert main(["bench", str(SICONOS_1C), "--backends", "auto,nsgs,exact",
                 "--repeats", "1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "2 of 3 backends certified (tol 1e-08)" in lines[0]
    rows = {line.split()[0]: line for line in lines[3:] if line.strip()}
    assert {"auto", "nsgs", "exact"} <= set(rows) and "refused" in rows["exact"]
    assert main(["bench", str(LMGC), "--backends", "auto,newton", "--repeats", "1",
                 "--tol", "1e-9", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["tol"] == 1e-9 and report["law"].startswith("coulomb")
    assert {r["backend"]: r["verdict"] for r in report["rows"]} == {"auto": "certified",
                                                                    "newton": "certified"}


@pytest.mark.parametrize("flags, match", [(["--mu", "0.3"], "--mu does not apply"),
                                          (["--law", "moreau"], "--law does not apply")])
def test_bench_refuses_law_flags_on_a_friction_file(capsys: pytest.CaptureFixture, flags: list,
                                                    match: str) -> None:
    assert main(["bench", str(SICONOS_1C), *flags]) == 2
    assert match in capsys.readouterr().err


def test_bench_names_a_file_that_is_no_problem(tmp_path: Path,
                                               capsys: pytest.CaptureFixture) -> None:
    junk = tmp_path / "notes.txt"
    junk.write_text("hello\n")
    assert main(["bench", str(junk)]) == 2
    err = capsys.readouterr().err
    assert "notes.txt" in err and "HDF5" in err
