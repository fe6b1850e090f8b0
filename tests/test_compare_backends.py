"""Every backend on the user's own impact (issue 27): ``iq.compare_backends``, ``impactqp
bench`` and ``impactqp backends``; a backend that is not installed refused by name with the
extra that installs it; third-party solvers silent unless ``verbose`` asks."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from declared_dependencies import declared

import impactqp as iq
from impactqp.cli.main import main
from impactqp.qp import backends
from impactqp.qp.backends import cvxpy_, qpsolvers_
from impactqp.verification.bench import default_backends

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
FEW = ["auto", "exact", "nnls", "clarabel", "osqp", "cvxpy", "cvxpy:SCS", "qpsolvers:daqp",
       "qpsolvers:highs", "gurobi"]


def without(monkeypatch: pytest.MonkeyPatch, module, solver: str) -> None:
    """Make ``solver`` look absent to the family ``module`` wraps (its availability check)."""
    have = tuple(s for s in module.installed_solvers() if s != solver)
    monkeypatch.setattr(module, "installed_solvers", lambda: have)


# --------------------------------------------------------------------------- the table
def test_every_certified_backend_agrees_with_an_independent_exact_answer() -> None:
    p = iq.random_impact(6, 4, seed=3)
    law = iq.Moreau(0.5)
    table = iq.compare_backends(p, law, FEW, repeats=2)
    reference = iq.moreau(p, 0.5, backend="exact").u_plus  # computed apart from the table
    assert [r.backend for r in table.runs] == FEW
    assert len(table.certified) >= 7
    assert table.best is not None and backends.REGISTRY[
        table[table.best].used.partition(":")[0]].exact
    assert table[table.best].error == 0.0
    for run in table.certified:
        assert run.result.certificate.ok and run.margin <= 1.0
        assert run.error <= 1e-8, run
        own = p.norm(run.result.u_plus - reference) / p.norm(p.u_minus)
        assert own <= 1e-8 and abs(own - run.error) <= 1e-8
        assert len(run.times) == 2 and run.time == pytest.approx(np.median(run.times))
        assert run.time > 0
    assert table["auto"].used != "auto"  # says which path auto took
    gurobi = table["gurobi"]
    assert gurobi.verdict == "refused" and "unknown backend 'gurobi'" in gurobi.reason
    assert np.isnan(gurobi.time) and np.isnan(gurobi.error) and gurobi.result is None


def test_a_backend_that_cannot_take_the_law_is_refused_with_its_reason() -> None:
    table = iq.compare_backends(iq.random_impact(5, 3, seed=1), iq.Newton(0.5),
                                ["exact", "isotonic"], repeats=1)
    assert table["exact"].certified
    refused = table["isotonic"]
    assert refused.verdict == "refused" and "'isotonic'" in refused.reason
    assert "impulse" in refused.reason


def test_a_backend_whose_solver_gives_up_is_a_failed_row(monkeypatch: pytest.MonkeyPatch) -> None:
    from impactqp.qp.backends import osqp_

    def gives_up(*args, **kwargs):
        raise iq.SolverError("osqp ended with status 'maximum iterations reached'")

    monkeypatch.setattr(osqp_, "solve", gives_up)
    table = iq.compare_backends(iq.newtons_cradle(3), iq.Moreau(1.0), ["exact", "osqp"],
                                repeats=1)
    failed = table["osqp"]
    assert failed.verdict == "failed" and "maximum iterations" in failed.reason
    assert failed.result is None and np.isnan(failed.error)
    assert [r.backend for r in table.certified] == ["exact"] and table.best == "exact"


def test_the_default_list_covers_every_backend_serving_the_law() -> None:
    names = default_backends(iq.Moreau(1.0))
    assert names[0] == "auto"
    served = {b["name"] for b in iq.available_backends() if b["laws"]["moreau"]}
    families = {n.partition(":")[0] for n in names[1:]}
    assert families == served
    assert {"cvxpy:SCS", "cvxpy:HIGHS", "qpsolvers:highs", "qpsolvers:quadprog"} <= set(names)
    assert "cvxpy:QUADPROG" not in names  # cvxpy does not run quadprog
    assert default_backends(iq.SectorLaw()) == ("auto", iq.SectorLaw.closed_form_backend)
    assert set(default_backends(iq.Coulomb(0.3))[1:]) == set(
        iq.friction.FRICTION_BACKENDS) - {"auto"}


def test_frictional_backends_compared_on_a_spinning_sphere() -> None:
    p = iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 5.0])
    table = iq.compare_backends(p, iq.Coulomb(0.3), repeats=1)
    assert len(table.certified) >= 4
    for run in table.certified:  # one contact: the answer is unique
        assert run.error <= 1e-7, run
    text = str(table)
    assert "Coulomb" in text and "several solutions" in text


def test_rows_and_text_say_the_same() -> None:
    table = iq.compare_backends(iq.newtons_cradle(3), iq.Moreau(1.0),
                                ["exact", "clarabel", "cvxpy:NOSUCH"], repeats=1)
    rows = table.to_rows()
    assert [r["backend"] for r in rows] == ["exact", "clarabel", "cvxpy:NOSUCH"]
    assert json.loads(json.dumps(rows)) == rows  # no NaN: None where a number does not apply
    assert rows[2]["verdict"] == "refused" and rows[2]["time_s"] is None
    assert rows[0]["error"] == table["exact"].error and rows[0]["time_s"] > 0
    lines = str(table).splitlines()
    assert lines[0].startswith("Moreau") and "2 of 3 backends certified" in lines[0]
    body = {line.split()[0]: line.split() for line in lines[3:] if line.strip()}
    assert body["exact"][-1] == "certified" and body["clarabel"][-1] == "certified"
    assert body["cvxpy:NOSUCH"][3] == "refused"


@pytest.mark.parametrize("bad, match", [
    ({"repeats": 0}, "repeats"), ({"repeats": 1.5}, "repeats"),
    ({"backends": "exact"}, "list"), ({"backends": []}, "non-empty"), ({"backends": [3]}, "names"),
    ({"tol": -1.0}, "tol")])
def test_bad_arguments_are_named(bad: dict, match: str) -> None:
    with pytest.raises(iq.InputError, match=match):
        iq.compare_backends(iq.newtons_cradle(3), iq.Moreau(1.0), **{"backends": ["exact"],
                                                                      **bad})
    with pytest.raises(iq.InputError, match="law"):
        iq.compare_backends(iq.newtons_cradle(3), "moreau")


# --------------------------------------------------------------------------- not installed
@pytest.mark.parametrize("module, family, solver, package", [
    (cvxpy_, "cvxpy", "SCS", "scs"), (cvxpy_, "cvxpy", "HIGHS", "highspy"),
    (qpsolvers_, "qpsolvers", "highs", "highspy"), (qpsolvers_, "qpsolvers", "daqp", "daqp")])
def test_a_solver_that_is_absent_is_refused_by_name_with_its_extra(
        monkeypatch: pytest.MonkeyPatch, module, family: str, solver: str, package: str) -> None:
    without(monkeypatch, module, solver)
    name = f"{family}:{solver}"
    with pytest.raises(iq.errors.UnknownBackendError) as info:
        iq.moreau(iq.newtons_cradle(3), 1.0, backend=name)
    message = str(info.value)
    assert f"backend '{name}' is not installed" in message
    assert f"pip install 'impactqp[solvers]' (adds {package})" in message
    table = iq.compare_backends(iq.newtons_cradle(3), iq.Moreau(1.0), ["exact", name],
                                repeats=1)
    assert table[name].verdict == "refused" and table[name].reason == message
    listed = {s["name"]: s for s in backends.sub_solvers(backends.REGISTRY[family])}
    assert not listed[name]["installed"] and "impactqp[solvers]" in listed[name]["install"]


def test_the_extra_named_in_the_refusal_is_the_one_pyproject_declares() -> None:
    core, extras = declared()
    assert "cvxpy-base" in core and "cvxpy" not in core  # no bundled scs/highspy
    for solver in backends.SOLVERS.values():
        if solver.extra == "":
            assert solver.package in core, solver
        elif solver.extra is not None:
            assert solver.package in extras[solver.extra], solver
            assert solver.package not in core, solver


def test_a_family_that_cannot_be_imported_is_refused_with_what_to_install(
        monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "qpsolvers", None)  # import qpsolvers fails
    monkeypatch.delitem(sys.modules, "impactqp.qp.backends.qpsolvers_")
    monkeypatch.setattr(backends, "_LOADED", {})
    with pytest.raises(iq.errors.UnknownBackendError,
                       match=r"backend 'qpsolvers' is not installed .*install qpsolvers"):
        iq.moreau(iq.newtons_cradle(3), 1.0, backend="qpsolvers:daqp")
    table = iq.compare_backends(iq.newtons_cradle(3), iq.Moreau(1.0),
                                ["exact", "qpsolvers:daqp"], repeats=1)
    assert table["qpsolvers:daqp"].verdict == "refused"
    assert "impactqp[solvers]" in table["qpsolvers:daqp"].reason


# --------------------------------------------------------------------------- quiet solvers
def test_third_party_output_does_not_reach_the_terminal(capfd: pytest.CaptureFixture) -> None:
    p = iq.newtons_cradle(3)
    capfd.readouterr()
    for backend in ["cvxpy:OSQP", "qpsolvers:highs", "qpsolvers:osqp", "qpsolvers:scs"]:
        for form in ["velocity", "impulse"]:
            assert iq.moreau(p, 1.0, backend=backend, form=form).ok
    iq.compare_backends(p, iq.Moreau(1.0), ["cvxpy:OSQP", "qpsolvers:highs"], repeats=1)
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_verbose_lets_the_solvers_speak(capfd: pytest.CaptureFixture) -> None:
    # OSQP (through cvxpy) prints a note on this impulse-form program from its C code
    p = iq.newtons_cradle(3)
    capfd.readouterr()
    iq.solve(p, iq.Moreau(1.0), backend="cvxpy:OSQP", form="impulse", verbose=2)
    out, err = capfd.readouterr()
    assert "Polishing" in out and "impactqp: DEBUG" in err
    iq.moreau(p, 1.0, backend="cvxpy:OSQP", form="impulse")
    assert capfd.readouterr().out == ""


FRESH = textwrap.dedent("""
    import warnings, impactqp as iq
    warnings.simplefilter("always")
    p = iq.newtons_cradle(3)
    for form in ("velocity", "impulse"):
        iq.solve(p, iq.Moreau(1.0), backend="qpsolvers:highs", form=form, verbose=VERBOSE)
    print("done")
""")


@pytest.mark.parametrize("verbose", [0, 2])
def test_the_highs_banner_of_a_fresh_process(capfd: pytest.CaptureFixture, verbose: int) -> None:
    # HiGHS prints its banner once per process, from C, when its first solver is made
    capfd.readouterr()
    run = subprocess.run([sys.executable, "-c", FRESH.replace("VERBOSE", str(verbose))],
                         timeout=240, check=True)
    assert run.returncode == 0
    out, err = capfd.readouterr()
    assert out.endswith("done\n")
    if verbose:
        assert "HiGHS" in out
    else:
        assert out == "done\n"
        assert "Warning" not in err and "HiGHS" not in err


# --------------------------------------------------------------------------- command line
def test_bench_prints_a_table_that_parses(capsys: pytest.CaptureFixture) -> None:
    code = main(["bench", str(EXAMPLES / "cradle.toml"), "--backends",
                 "exact,clarabel,cvxpy:NOSUCH", "--repeats", "1"])
    assert code == 0
    lines = capsys.readouterr().out.splitlines()
    assert "2 of 3 backends certified" in lines[0] and lines[2].split()[:2] == ["backend", "time"]
    rows = {line.split()[0]: line for line in lines[3:] if line.strip()}
    assert set(rows) == {"exact", "clarabel", "cvxpy:NOSUCH"}
    assert "refused" in rows["cvxpy:NOSUCH"] and "not installed" in rows["cvxpy:NOSUCH"]


def test_bench_json_with_the_law_from_flags(capsys: pytest.CaptureFixture) -> None:
    code = main(["bench", str(EXAMPLES / "cradle.toml"), "--law", "newton", "--e", "0.5",
                 "--backends", "exact,nnls,isotonic", "--repeats", "2", "--json"])
    assert code == 0
    report = json.loads(capsys.readouterr().out)
    assert report["law"] == "newton" and report["repeats"] == 2
    rows = {r["backend"]: r for r in report["rows"]}
    assert rows["exact"]["verdict"] == rows["nnls"]["verdict"] == "certified"
    assert rows["nnls"]["error"] <= 1e-8 and rows["exact"]["time_s"] > 0
    assert rows["isotonic"]["verdict"] == "refused" and rows["isotonic"]["reason"]
    content = iq.load_problem(EXAMPLES / "cradle.toml")
    expected = iq.newton(content.problem, 0.5, backend="exact").u_plus
    assert report["best"] in ("exact", "nnls")
    assert np.allclose(iq.solve(content.problem, iq.Newton(0.5), backend=report["best"]).u_plus,
                       expected, atol=1e-12)


def test_bench_refuses_bad_flags_in_its_own_words(capsys: pytest.CaptureFixture) -> None:
    assert main(["bench", str(EXAMPLES / "cradle.toml"), "--repeats", "0"]) == 2
    assert "repeats" in capsys.readouterr().err


def test_backends_lists_the_registry_and_what_to_install(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture) -> None:
    without(monkeypatch, cvxpy_, "SCS")
    assert main(["backends", "--json"]) == 0
    rows = {r["name"]: r for r in json.loads(capsys.readouterr().out)["backends"]}
    assert {b["name"] for b in iq.available_backends()} <= set(rows)
    assert rows["clarabel"]["installed"] and "coulomb" in rows["clarabel"]["laws"]
    assert rows["cvxpy:SCS"] == {"name": "cvxpy:SCS", "installed": False,
                                 "forms": ["velocity", "impulse", "cone"],
                                 "laws": ["moreau", "newton", "fremond"],
                                 "install": "pip install 'impactqp[solvers]' (adds scs)",
                                 "via": "cvxpy"}
    assert main(["backends"]) == 0
    text = capsys.readouterr().out
    scs = next(line for line in text.splitlines() if line.split()[:1] == ["cvxpy:SCS"])
    assert scs.split()[1] == "no" and "install: pip install 'impactqp[solvers]'" in scs
    kernel = next(line for line in text.splitlines() if line.startswith("kernel"))
    assert kernel.split()[1] == "yes" and "coulomb" in kernel


def test_threads_share_one_redirection_and_restore_everything() -> None:
    import os
    import threading
    import time
    import warnings

    from impactqp.qp.backends.quiet import quiet

    before = (sys.stdout, list(warnings.filters), os.fstat(1).st_ino)
    inside: list[tuple[bool, int]] = []
    start = threading.Barrier(4)

    def work(delay: float) -> None:
        start.wait()
        with quiet():
            time.sleep(delay)
            inside.append((sys.stdout is before[0], os.fstat(1).st_ino))

    threads = [threading.Thread(target=work, args=(d,)) for d in (0.05, 0.0, 0.1, 0.02)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    null = os.stat(os.devnull).st_ino
    assert inside and all(not same and ino == null for same, ino in inside)
    assert (sys.stdout, list(warnings.filters), os.fstat(1).st_ino) == before
