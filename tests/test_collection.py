"""Whole collections of friction problems: every file of a folder solved and recorded once,
the same records in this process, on child processes and on a Dask cluster, resumed after a
crash without solving anything twice, stopped at a time limit and never called solved."""

from __future__ import annotations

import gzip
import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
import impactqp.collection as collection
import impactqp.io.collection as collection_io
from impactqp.collection import run_collection
from impactqp.io.collection import Task, collection_files
from impactqp.io.deadline import SolverProcess
from impactqp.io.journal import Journal

ROOT = Path(__file__).resolve().parents[1]
FILES = [ROOT / "tests/data/fclib" / name for name in (
    "FrictionContact3D_1c.dat", "FC2D_SliderCrankLagrangian00000.dat",
    "LMGC_GlobalFrictionContactProblem00046.hdf5", "Box_Stacks-i0122-82-5.hdf5",
    "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5")] + [
    ROOT / "benchmarks/data/fclib/NESpheres_10_1.dat.gz"]
#: what a record says apart from times, the same wherever it was solved
SAME = ("file", "method", "status", "error_name", "contacts", "d", "mu_min", "mu_max",
        "iterations", "backend", "tol")


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The repository's small problems, one in a subfolder, and three hostile files."""
    root = tmp_path_factory.mktemp("collection")
    (root / "global").mkdir()
    for path in FILES:
        shutil.copy(path, root / ("global" if "Global" in path.name else "") / path.name)
    (root / "garbage.hdf5").write_bytes(np.random.default_rng(0).bytes(3000))
    (root / "truncated.hdf5").write_bytes(FILES[3].read_bytes()[:4000])
    (root / "cut.dat.gz").write_bytes(gzip.compress(FILES[1].read_bytes())[:200])
    (root / "notes.txt").write_text("not a problem file")
    return root


@pytest.fixture(scope="module")
def local(folder: Path, tmp_path_factory: pytest.TempPathFactory) -> list[dict]:
    out = tmp_path_factory.mktemp("local") / "records.jsonl"
    return run_collection(folder, out, methods=("auto", "nsgs")).records


def same(a: list[dict], b: list[dict]) -> None:
    assert [{k: r[k] for k in SAME} for r in a] == [{k: r[k] for k in SAME} for r in b]
    for x, y in zip(a, b, strict=True):
        for key in ("abh_error", "r_norm"):
            assert (x[key] is None) == (y[key] is None)
            if x[key] is not None:
                assert y[key] == pytest.approx(x[key], rel=1e-9, abs=1e-300)


def test_every_file_is_recorded_once_per_method(folder: Path, local: list[dict]) -> None:
    files = collection_files(folder)
    assert "notes.txt" not in files and "global/LMGC_GlobalFrictionContactProblem00046.hdf5" \
        in files and len(files) == 9
    assert [(r["file"], r["method"]) for r in local] == \
        [(f, m) for f in files for m in ("auto", "nsgs")]
    certified = [r for r in local if r["status"] == "certified"]
    assert len(certified) == 12 and all(r["abh_error"] <= 1e-8 for r in certified)
    for r in certified:  # the record holds the answer's own figures: recomputed here
        problem = iq.load_fclib(folder / r["file"])
        assert (r["contacts"], r["d"]) == (problem.n_contacts, problem.contact_dim)
        assert r["mu_min"] == pytest.approx(np.min(problem.mu))
        if r["method"] == "auto":
            answer = iq.solve_friction(problem)
            assert r["backend"] == answer.backend
            assert r["r_norm"] == pytest.approx(np.linalg.norm(answer.r), rel=1e-9)
    hostile = {r["file"]: r for r in local if r["status"] == "error"}
    assert set(hostile) == {"garbage.hdf5", "truncated.hdf5", "cut.dat.gz"}
    assert {r["error_name"] for r in hostile.values()} == {"ProblemFileError"}


def test_output_is_json_lines(folder: Path, tmp_path: Path) -> None:
    out = tmp_path / "one.jsonl"
    run = run_collection(folder, out, methods="auto")
    lines = out.read_text().splitlines()
    assert len(lines) == run.new == 9 and run.skipped == 0
    assert [json.loads(line) for line in lines] == \
        sorted(run.records, key=lambda r: lines.index(json.dumps(r, separators=(",", ":"))))


def test_child_processes_give_the_same_records(folder: Path, tmp_path: Path,
                                               local: list[dict]) -> None:
    run = run_collection(folder, tmp_path / "two.jsonl", methods=("auto", "nsgs"), n_jobs=2,
                         time_limit=120.0)
    same(local, run.records)


@pytest.mark.parametrize("limit", [None, 120.0])
def test_dask_local_cluster_gives_the_same_records(folder: Path, tmp_path: Path,
                                                   local: list[dict],
                                                   limit: float | None) -> None:
    """Without a limit: workers as threads of this process, solving in them. With one:
    workers as daemon processes (as a real cluster's), each starting a supervisor subprocess
    that forks the solving children."""
    distributed = pytest.importorskip("distributed", reason="the optional dask extra")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=limit is not None,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        run = run_collection(folder, tmp_path / "dask.jsonl", methods=("auto", "nsgs"),
                             client=client, time_limit=limit)
        assert set(client.run(lambda: 1)) == set(client.scheduler_info()["workers"])
    same(local, run.records)


def test_groups_hold_every_task_once_largest_files_first(folder: Path) -> None:
    tasks = [Task(str(folder), f, m, 1e-8) for f in collection_files(folder)
             for m in ("auto", "nsgs")]
    size = {f: (folder / f).stat().st_size for f in collection_files(folder)}
    for workers, expected in ((1, 2), (2, 1), (8, 1)):  # 18 tasks: >= 8 groups per worker
        groups = collection._groups(tasks, workers)
        assert {len(g) for g in groups[:-1]} == {expected} and 1 <= len(groups[-1]) <= expected
        flat = [t for g in groups for t in g]
        assert sorted(flat) == sorted(tasks)
        assert [size[t.file] for t in flat] == sorted((size[t.file] for t in tasks),
                                                      reverse=True)
    many = tasks * 40  # 720 tasks: groups of at most GROUP
    assert max(len(g) for g in collection._groups(many, 2)) == collection.GROUP


def test_dask_groups_give_the_same_records_and_a_failing_one_is_split(
        folder: Path, tmp_path: Path, local: list[dict],
        monkeypatch: pytest.MonkeyPatch) -> None:
    """One worker: groups of two problems. A group whose task fails (as when its worker dies)
    is run again one problem per task: only the problem that fails is an error record."""
    distributed = pytest.importorskip("distributed", reason="the optional dask extra")
    bad = "global/LMGC_GlobalFrictionContactProblem00046.hdf5"
    solve = collection.solve_task

    def fragile(task: Task) -> dict:
        if task.file == bad and task.method == "nsgs":
            raise MemoryError("a problem that takes its worker down")
        return solve(task)

    monkeypatch.setattr(collection, "solve_task", fragile)
    sizes: list[int] = []
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=":0") as cluster, \
            distributed.Client(cluster) as client:
        submit = client.submit
        client.submit = lambda f, tasks, *a, **k: sizes.append(len(tasks)) or submit(
            f, tasks, *a, **k)
        run = run_collection(folder, tmp_path / "dask.jsonl", methods=("auto", "nsgs"),
                             client=client)
    assert sizes == [2] * 9 + [1, 1]  # the failed pair again, one problem per task
    failed = [r for r in run.records if r["file"] == bad and r["method"] == "nsgs"]
    assert [(r["status"], r["error_name"]) for r in failed] == [("error", "MemoryError")]
    rest = [r for r in run.records if r not in failed]
    same([r for r in local if (r["file"], r["method"]) != (bad, "nsgs")], rest)


def test_a_solver_that_kills_its_process_is_an_error_record(
        folder: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(collection_io, "solve_friction", lambda *a, **k: os._exit(3))
    proc = SolverProcess(method="fork")  # the child inherits the patched solver
    try:
        died = proc.run(Task(str(folder), FILES[0].name, "auto", 1e-8), 60.0)
        assert (died["status"], died["error_name"], died["contacts"]) == \
            ("error", "RuntimeError", 1)
        assert "exit 3" in died["message"]
        monkeypatch.undo()  # the next child is forked afresh, with the real solver
        monkeypatch.setattr(collection_io, "solve_friction", iq.solve_friction)
        assert proc.run(Task(str(folder), FILES[0].name, "auto", 1e-8), 60.0)["status"] == \
            "certified"
    finally:
        proc.close()


def test_resume_solves_only_what_is_missing(folder: Path, tmp_path: Path,
                                            monkeypatch: pytest.MonkeyPatch) -> None:
    out = tmp_path / "resumed.jsonl"
    first = run_collection(folder, out)
    lines = out.read_text().splitlines(keepends=True)
    solved = [i for i, line in enumerate(lines) if '"certified"' in line]
    kept = [line for i, line in enumerate(lines) if i not in solved[-2:]]
    out.write_text("".join(kept) + lines[solved[-1]][:25])  # a crash in the middle of a line
    calls = []
    real = collection_io.solve_friction
    monkeypatch.setattr(collection_io, "solve_friction",
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    again = run_collection(folder, out)
    assert (len(calls), again.new, again.skipped) == (2, 2, 7)
    same(first.records, again.records)
    assert len(Journal(out).records()) == 9 and out.read_text().endswith("}\n")
    assert run_collection(folder, out).new == 0 and len(calls) == 2


def test_tiny_time_limit_is_never_a_solve(folder: Path, tmp_path: Path) -> None:
    run = run_collection(folder, tmp_path / "limit.jsonl", time_limit=1e-3)
    stopped = [r for r in run.records if r["status"] == "time limit"]
    # the global problems take longer than 1 ms to read and reduce alone
    assert {"Box_Stacks-i0122-82-5.hdf5", "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5"} <= \
        {r["file"] for r in stopped}
    assert all(r["seconds"] >= 1e-3 and r["abh_error"] is None for r in stopped)
    assert not any(r["status"] == "certified" and r["read_seconds"] + r["seconds"] > 1e-3
                   for r in run.records)


def test_a_damaged_journal_line_is_named(folder: Path, tmp_path: Path) -> None:
    out = tmp_path / "damaged.jsonl"
    out.write_text('{"file": "a", "method": "auto"}\nnot json\n{"file": "b"}\n')
    with pytest.raises(iq.errors.ProblemFileError, match="line 2"):
        run_collection(folder, out)


def test_bad_arguments(folder: Path, tmp_path: Path) -> None:
    out = tmp_path / "x.jsonl"
    for kwargs in ({"methods": ()}, {"methods": ("auto", "auto")}, {"methods": "lemke"},
                   {"time_limit": 0.0}, {"time_limit": float("nan")}, {"n_jobs": 0},
                   {"tol": -1.0},
                   {"scheduler": "tcp://x:1", "client": object()}):
        with pytest.raises(iq.InputError):
            run_collection(folder, out, **kwargs)
    with pytest.raises(iq.InputError, match="not a folder"):
        run_collection(tmp_path / "missing", out)
    assert not out.exists()


def test_benchmark_command_runs_a_collection(folder: Path, tmp_path: Path,
                                             capsys: pytest.CaptureFixture) -> None:
    from benchmarks.__main__ import main

    out = tmp_path / "bench.jsonl"
    assert main(["run", "--suite", "fclib", "--collection", str(folder), "--output", str(out),
                 "--siconos-python", "", "--methods", "auto,nsgs", "--no-progress"]) == 0
    text = capsys.readouterr().out
    assert "| auto | 6 | 0 | 0 | 3 |" in text and "| nsgs | 6 | 0 | 0 | 3 |" in text
    assert len(out.read_text().splitlines()) == 18 and out.with_suffix(".png").is_file()
    with pytest.raises(SystemExit):
        main(["run", "--suite", "fclib"])  # no --collection


def test_siconos_answers_are_judged_by_impactqp(tmp_path: Path) -> None:
    from benchmarks.collection import run_fclib_collection, summary
    from benchmarks.peers import SICONOS_PYTHON, siconos_status

    if siconos_status(SICONOS_PYTHON) is not None:
        pytest.skip("Siconos is not installed for /usr/bin/python3")
    for path in FILES[:3]:
        shutil.copy(path, tmp_path / path.name)
    records = run_fclib_collection(tmp_path, tmp_path / "out.jsonl", time_limit=60.0)
    peer = [r for r in records if r["method"].startswith("siconos:")]
    assert {(r["file"], r["method"]) for r in peer} == \
        {(f.name, f"siconos:{s}") for f in (FILES[0], FILES[2])
         for s in ("NSGS", "NSN_AC", "PROX")} | {(FILES[1].name, "siconos:NSGS")}  # 2-D: NSGS
    for r in peer:  # the verdict is the ABH error impactqp recomputed from Siconos' r
        assert r["status"] in ("certified", "not certified")
        assert (r["abh_error"] <= 1e-8) == (r["status"] == "certified")
    both = [f for f in {r["file"] for r in records} if all(
        r["status"] == "certified" for r in records
        if r["file"] == f and r["method"] in ("auto", "siconos:NSGS"))]
    assert f"geometric mean over the {len(both)} problems" in summary(records)


def test_summary_by_hand(tmp_path: Path) -> None:
    from benchmarks.collection import summary

    def rec(file: str, method: str, status: str, seconds: float) -> dict:
        return {"file": file, "method": method, "status": status, "seconds": seconds, "d": 3}

    records = [rec("a", "auto", "certified", 1.0), rec("a", "siconos:NSGS", "certified", 4.0),
               rec("b", "auto", "certified", 2.0), rec("b", "siconos:NSGS", "certified", 2.0),
               rec("c", "auto", "certified", 1.0), rec("c", "siconos:NSGS", "not certified", 9.0)]
    text = summary(records, tmp_path / "profile.png")
    # (1/4 · 2/2)^(1/2) = 0.5 over a and b; c is not certified by NSGS
    assert "over the 2 problems both certify: 0.50×" in text
    assert "| auto | 3 | 0 | 0 | 0 |" in text and "| siconos:NSGS | 2 | 1 | 0 | 0 |" in text
    assert (tmp_path / "profile.png").read_bytes()[:4] == b"\x89PNG"


def test_scaling_estimate_on_idle_cores_by_hand() -> None:
    from benchmarks.collection_scaling import ClusterRun

    def run(seconds: float, cpu: list[float], client: float, rates: list[float],
            cores: int = 2) -> float:
        return ClusterRun([], seconds, 0.0, cpu, client, rates, [], []).idle_cores(cores)

    # one worker, 40 s of which 0.05/s idle: 20 - 2 = 18 s of work, on 0.95 of a core
    assert run(40.0, [20.0], 2.0, [0.05, 0.05]) == pytest.approx(18.0 / 0.95)
    # two workers on 2 cores: all the processes' work, 11 - 1 + 13 - 1 + 3 - 1, on the
    # 2 - 0.15 cores their idle rates leave
    assert run(20.0, [11.0, 13.0], 3.0, [0.05, 0.05, 0.05]) == pytest.approx(24.0 / 1.85)
    # on 4 cores: the workers' 22 s shared evenly, each on 0.95 of a core
    assert run(20.0, [11.0, 13.0], 3.0, [0.05, 0.05, 0.05], 4) == pytest.approx(22.0 / 1.9)
