"""The benchmark suite runs end to end (smoke suite), writes its reports and never crashes."""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks import families  # noqa: E402
from benchmarks.methods import METHODS, Method  # noqa: E402
from benchmarks.runner import run_suite  # noqa: E402


def _broken(case: families.Case):
    def solve():
        raise RuntimeError("deliberate failure")
    return solve, lambda raw: raw


@pytest.fixture(scope="module")
def smoke(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench")
    methods = [*METHODS, Method("broken", "raw", _broken)]
    records = run_suite("smoke", out, methods=methods, progress=False)
    return out, records


def test_reports_are_written(smoke):
    out, _ = smoke
    for name in ("results.csv", "results.json", "summary.md", "plot.png"):
        assert (out / name).stat().st_size > 0, name
    rows = list(csv.DictReader(open(out / "results.csv")))
    assert {"median_s", "p90_s", "max_error", "success_rate", "peak_mb"} <= set(rows[0])
    data = json.loads((out / "results.json").read_text())
    assert data["meta"]["suite"] == "smoke" and len(data["rows"]) == len(rows)
    assert (out / "plot.png").read_bytes()[:4] == b"\x89PNG"
    assert "## Targets" in (out / "summary.md").read_text()


def test_impactqp_is_exact_on_chains(smoke):
    _, records = smoke
    chains = [r for r in records if r["family"] == "cradle" and r["method"].startswith("iq:")
              and r["status"] != "skipped"]
    assert chains
    for r in chains:
        assert r["status"] == "ok", r
        assert r["error"] <= 1e-9 and r["times"], r


def test_failing_method_is_recorded(smoke):
    _, records = smoke
    broken = [r for r in records if r["method"] == "broken" and r["status"] != "skipped"]
    assert len(broken) >= 3 and all(r["status"] == "failed" for r in broken)
    assert all("deliberate failure" in r["message"] for r in broken)


def test_siconos_rows_are_ok_or_skipped(smoke):
    _, records = smoke
    peer = [r for r in records if r["group"] == "peer"]
    assert peer and {r["status"] for r in peer} <= {"ok", "inaccurate", "failed", "skipped"}
    lemke3 = [r for r in peer if r["method"] == "siconos:lemke" and r["size"] == 3]
    assert lemke3 and lemke3[0]["status"] in ("ok", "skipped")


def test_missing_siconos_is_a_skip_not_a_failure(tmp_path):
    records = run_suite("smoke", tmp_path, methods=[], siconos_python=sys.executable,
                        progress=False)
    peer = [r for r in records if r["group"] == "peer"]
    assert peer and all(r["status"] == "skipped" for r in peer)
    assert "siconos not importable" in peer[0]["message"]


def test_disc_packing_geometry():
    p = families.disc_packing(4, seed=1)
    W = p.W.toarray()
    assert p.n_dof == 32 and p.n_contacts == 33  # 3·16 − 4·4 + 1 touching pairs
    # each column: −n on one disc, +n on another, |n| = 1
    assert abs(W[0::2].sum(axis=0)).max() < 1e-12 and abs(W[1::2].sum(axis=0)).max() < 1e-12
    assert abs((W ** 2).sum(axis=0) - 2.0).max() < 1e-12
    assert (abs(W) > 0).sum(axis=0).max() <= 4


def test_progress_bar_stays_out_of_logs(tmp_path, capsys):
    run_suite("smoke", tmp_path, methods=[], siconos_python="", progress=True)
    err = capsys.readouterr().err
    assert "\r" not in err  # stderr is not a terminal here: no bar, no carriage returns


def test_plot_keeps_methods_apart(smoke):
    from benchmarks import report

    rows = report.aggregate(smoke[1])
    styles = report._styles(rows)
    for _, groups in report.PANELS:
        members = [m for m in styles if any(r["method"] == m and r["group"] in groups
                                            for r in rows)]
        looks = {(styles[m]["color"], styles[m]["marker"]) for m in members}
        assert len(looks) == len(members)  # no two methods of a panel look alike
    assert report._size_label(100_000) == "10$^{5}$" and report._size_label(50) == "50"


def test_sweep_worker_count_is_an_option(capsys):
    from benchmarks.__main__ import main
    from benchmarks.report import targets
    from benchmarks.sweeps import run_sweeps

    with pytest.raises(SystemExit) as exc:
        main(["run", "--n-jobs", "0"])
    assert exc.value.code == 2 and "--n-jobs must be at least 1" in capsys.readouterr().err
    rows = run_sweeps("quick", n_jobs=3)
    assert [r["method"] for r in rows] == ["iq:fremond_map n_jobs=1", "iq:fremond_map n_jobs=3"]
    assert all(r["status"] == "ok" for r in rows)  # identical maps
    for r in rows:
        r["median_s"] = sorted(r["times"])[len(r["times"]) // 2]
    (line,) = [t for t in targets(rows) if t[0].startswith("sweep")]
    assert "3 local processes" in line[0] and line[2] == "identical"
    assert run_sweeps("smoke") == []
