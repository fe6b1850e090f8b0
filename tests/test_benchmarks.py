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


# --- runs: simulations beside Siconos, per-impact timings, start-up ----------------------------
TINY_SIMULATIONS = {"quick": ([("ball", 1, 40), ("cradle", 2, 30), ("column", 2, 30)], 1)}
NO_SICONOS = "/nonexistent/python3"


def _siconos_here() -> bool:
    from benchmarks.simulation import SICONOS_PYTHON, siconos_available

    return siconos_available(SICONOS_PYTHON)[0] is not None


def test_simulations_without_siconos_are_skipped_not_failed(monkeypatch):
    from benchmarks import dynamics

    monkeypatch.setattr(dynamics, "SIMULATIONS", TINY_SIMULATIONS)
    rows = dynamics.run_simulations("quick", NO_SICONOS)
    if _siconos_here() and any(r["group"] == "peer" and r["status"] == "ok" for r in rows):
        pytest.skip("siconos imports in this Python itself")
    assert [r["family"] for r in rows] == ["sim-ball", "sim-ball", "sim-cradle", "sim-cradle",
                                           "sim-column", "sim-column"]
    mine = [r for r in rows if r["method"] == "iq:simulate"]
    peer = [r for r in rows if r["method"] == "siconos:MoreauJeanOSI"]
    assert all(r["status"] == "ok" and len(r["times"]) == 1 and r["error"] is None
               for r in mine)
    assert all(r["status"] == "skipped" and "siconos not importable" in r["message"]
               and NO_SICONOS in r["message"] for r in peer)
    assert mine[0]["size"] == 40 and mine[1]["size"] == 2  # ball: steps; others: balls
    assert dynamics.run_simulations("smoke", NO_SICONOS) == []
    # a server in a Python without siconos answers each run with the error, never hangs
    from benchmarks.simulation import SiconosServer

    with SiconosServer(sys.executable) as server, pytest.raises(RuntimeError,
                                                                match="No module named"):
        server.run("ball", 1, 10)


@pytest.mark.skipif(not _siconos_here(), reason="python3-siconos not installed")
def test_simulations_reproduce_siconos_interleaved(monkeypatch, tmp_path):
    from benchmarks import dynamics, report, simulation

    monkeypatch.setattr(dynamics, "SIMULATIONS", TINY_SIMULATIONS)
    rows = dynamics.run_simulations("quick")
    assert len(rows) == 6 and all(r["status"] == "ok" and r["times"] for r in rows), rows
    # the same steps in both codes: trajectories equal to round-off (impacts included: the
    # ball lands after ~90 steps only, so check the bead column's, which start at once)
    assert all(r["error"] <= 1e-12 for r in rows)
    with simulation.SiconosServer(simulation.SICONOS_PYTHON) as server:
        _, theirs = server.run("ball", 1, 120)  # past the first impact (step 91)
        with pytest.raises(RuntimeError, match="siconos"):
            server.run("column", 0, 10)  # no bead: Siconos fails, the server goes on
    _, mine = simulation.impactqp_run("ball", 1, 120)
    assert len(theirs["q"]) == 121 and simulation.agreement(mine, theirs) <= 1e-12
    assert theirs["v"][92] > 0 > theirs["v"][90]  # it bounced
    theirs["q"][-1] += 1e-6
    assert simulation.agreement(mine, theirs) == pytest.approx(1e-6, rel=1e-6)
    records = report.write_all(rows, tmp_path, {"suite": "t", "seconds": 0,
                                                "timing_budget_s": 0, "max_repeats": 1,
                                                "accurate_below": 1e-6})
    assert (tmp_path / "plot.png").stat().st_size > 0  # run families are not plotted
    assert "## sim-column" in (tmp_path / "summary.md").read_text() and records


def test_per_impact_rows(monkeypatch):
    from benchmarks import dynamics

    monkeypatch.setattr(dynamics, "PER_IMPACT", {"quick": (1.0, [3], (2, 0.0))})
    ball, lzb = dynamics.run_per_impact("quick")
    seconds, impacts = dynamics.event_ball_run(1.0)
    assert impacts == 1  # first landing at √(2/g) ≈ 0.45 s, the next at ≈ 1.3 s
    assert ball["family"] == "event-ball" and ball["size"] == 1.0 and ball["status"] == "ok"
    assert len(ball["times"]) == 1 and "1 certified impacts" in ball["reference"]
    assert lzb["family"] == "lzb" and lzb["size"] == 3 and lzb["status"] == "ok"
    assert len(lzb["times"]) == 1 and lzb["times"][0] > 0
    assert "CPU" in lzb["reference"] and "DOP853 steps" in lzb["reference"]
    assert dynamics.run_per_impact("smoke") == []
    assert dynamics.run_startup("quick") == []


def test_fresh_problem_method_builds_and_is_exact(smoke):
    _, records = smoke
    fresh = [r for r in records if r["method"] == "iq:fresh"]
    ran = [r for r in fresh if r["status"] != "skipped"]
    assert ran and all(r["family"] == "random" for r in ran)
    assert all(r["status"] == "ok" and r["error"] <= 1e-9 for r in ran)
    assert all(r["status"] == "skipped" for r in fresh if r["family"] != "random")


def _agg(family, size, method, median, error=None, reference=""):
    return {"family": family, "size": size, "method": method, "group": "impactqp",
            "median_s": median, "max_error": error, "reference": reference,
            "status": "ok", "success_rate": 1, "ok": 1, "ran": 1, "note": "", "message": ""}


def test_targets_of_the_runs():
    from benchmarks.report import WHY_MISSED, summary_markdown, targets
    from benchmarks.startup import first_call_extra

    rows = [
        _agg("sim-ball", 2000, "iq:simulate", 2e-3, 1e-14),
        _agg("sim-ball", 2000, "siconos:MoreauJeanOSI", 1e-3, 1e-14),
        _agg("sim-cradle", 5, "iq:simulate", 1e-3, 1e-9),
        _agg("sim-cradle", 5, "siconos:MoreauJeanOSI", 2e-3, 1e-9),
        _agg("sim-column", 100, "iq:simulate", 0.5, 1e-14),
        _agg("sim-column", 100, "siconos:MoreauJeanOSI", 1.0, 1e-14),
        _agg("event-ball", 10, "iq:event-driven", 1e-4, reference="168 impacts"),
        _agg("lzb", 10, "iq:lzb", 1e-3), _agg("lzb", 100, "iq:lzb", 0.1),
        _agg("random", 10, "iq:auto", 2e-5), _agg("random", 10, "iq:fresh", 1e-4),
        _agg("random", 10, "siconos:lemke", 1e-5),
        _agg("startup", 4, "iq:first calls", 0.4, reference="import 300 ms"),
    ]
    found = {t.split(":")[0]: (m, v) for t, m, v in targets(rows)}
    assert found["Siconos' BouncingBallTS, 2000 steps, same trajectory (≤ 1e-12)"][1] \
        == "MISSED by 2.0×"
    assert found["5-ball cradle on pendulums, Moreau–Jean, 1000 steps"][1] == "met"
    assert found["100-bead column, 1000 steps"][1] == "MISSED by 1.7×"
    assert found["event-driven bouncing ball, T = 10 s"] == (
        "100 µs per impact (168 impacts)", "met")
    assert found["LZB 10-ball steel chain"][1] == "met"
    assert found["LZB 100-ball steel chain"][1] == "MISSED by 3.3×"
    assert found["random dense m = 10, repeat solve"][1] == "met"
    assert found["random dense m = 10, built fresh + solved"][1] == "met"
    assert found["first calls in a fresh process, numba cache filled"][1] == "met"
    rows[1]["median_s"] = 1.0  # faster than Siconos, but no longer the same trajectory
    rows[0]["max_error"] = 1e-9
    found = {t.split(":")[0]: v for t, _, v in targets(rows)}
    assert found["Siconos' BouncingBallTS, 2000 steps, same trajectory (≤ 1e-12)"] \
        == "MISSED (trajectories differ)"
    # every target that can be missed says why in the summary
    for key in ("100-bead column, 1000 steps", "LZB 100-ball steel chain"):
        assert key in WHY_MISSED
    text = summary_markdown(rows, {"suite": "t", "seconds": 0, "timing_budget_s": 0,
                                   "max_repeats": 1, "accurate_below": 1e-6})
    assert "*LZB 100-ball steel chain*" in text and "*100-bead column, 1000 steps*" in text
    assert first_call_extra({"import": 1.0, "a": 0.5, "a (warm call)": 0.1, "b": 0.2,
                             "b (warm call)": 0.2}) == pytest.approx(0.4)


# --- friction: the Dolan–Moré profile, the data, the report, the peer ------------------------
def test_performance_profile_by_hand():
    from benchmarks.perf_profile import profile, ratios, tau_grid

    inf = float("inf")
    # p1: A and B tie; p2: B fails; p3: every solver fails; p4: C fails, A 3× the best
    times = {"A": [1.0, 2.0, inf, 3.0], "B": [1.0, inf, inf, 1.0], "C": [2.0, 4.0, inf, inf]}
    r = ratios(times)
    assert list(r["A"]) == [1.0, 1.0, inf, 3.0]
    assert list(r["B"]) == [1.0, inf, inf, 1.0]
    assert list(r["C"]) == [2.0, 2.0, inf, inf]
    rho = profile(times, [1.0, 1.9, 2.0, 3.0, 1e9, inf])
    assert list(rho["A"]) == [0.5, 0.5, 0.5, 0.75, 0.75, 0.75]  # never p3: all failed there
    assert list(rho["B"]) == [0.5, 0.5, 0.5, 0.5, 0.5, 0.5]  # the tie counts for both
    assert list(rho["C"]) == [0.0, 0.0, 0.5, 0.5, 0.5, 0.5]  # ρ(∞): the share solved
    assert list(ratios({"A": [float("nan")], "B": [2.0]})["A"]) == [inf]  # NaN = failed
    grid = tau_grid(times)
    assert grid[0] == 1.0 and 3.0 in grid and grid[-1] >= 10.0
    with pytest.raises(ValueError, match="positive"):
        ratios({"A": [0.0]})


def test_suite_problems_load():
    import numpy as np

    from benchmarks import friction_data

    expected = {"NESpheres-10": (9, 0.8), "BoxesStack1": (52, 0.7), "Spheres": (356, 0.7),
                "KaplasTower": (570, 0.3), "LMGC-00046": (9, 0.3)}
    for name, (contacts, mu) in expected.items():
        case = friction_data.load(name)
        assert case.n_contacts == contacts and np.all(case.problem.mu == mu), name
        assert case.family == f"friction:{name}"
    W = friction_data.load("NESpheres-10").problem.dense_W()  # dense storage, column-major
    assert W[0, 0] == 0.2 and np.abs(W - W.T).max() <= 1e-15
    W = friction_data.load("BoxesStack1").problem.dense_W()  # sparse-block storage
    assert np.abs(W - W.T).max() <= 1e-12 * np.abs(W).max()
    assert np.linalg.matrix_rank(W) == 78  # 156 rows: rank-deficient, as the README says


def test_spheres_in_a_row_geometry():
    import numpy as np

    import impactqp as iq
    from benchmarks.friction_impacts import MU, RADIUS, spheres_in_a_row

    one = spheres_in_a_row(1)
    # W of a sphere on a plane: 1/m in the normal, 1/m + R²/I = 1 + 5/2 in each tangent
    assert np.allclose(one.local.W, np.diag([1.0, 3.5, 3.5]))
    rolling = np.array([2.0 * RADIUS, 0.0, 0.0, 0.0, 2.0, 0.0])  # v = ω × (R e_z)
    assert np.allclose(one.H.T @ rolling, 0.0)  # the contact point does not move
    three = spheres_in_a_row(3)
    assert three.n_contacts == 5 and np.allclose(three.local.W, three.local.W.T)
    assert np.linalg.eigvalsh(three.local.W).min() > -1e-12
    # a single plastic impact in closed form: r_n = −q_n / W_nn, sliding when the sticking
    # impulse lies outside the cone, against the solver
    q = one.local.q
    rn = -q[0]
    stick = -q[1:] / 3.5
    rt = stick if np.linalg.norm(stick) <= MU * rn else -MU * rn * q[1:] / np.linalg.norm(q[1:])
    res = iq.solve_friction(one.local)
    assert np.allclose(res.r, [rn, *rt], atol=1e-8)


def _frow(problem, method, status, median, error=1e-9, size=10):
    return {"family": f"friction:{problem}", "size": size, "method": method,
            "group": "peer" if method.startswith("siconos") else "impactqp",
            "status": status, "median_s": median, "max_error": error, "success_rate": 1,
            "ok": 1, "ran": 1, "note": "", "message": "", "reference": ""}


def test_friction_report_by_hand(tmp_path):
    import math

    from benchmarks import friction_report

    rows = []
    for problem, size, auto, nsgs, nsgs_status in (("a", 5, 1e-3, 4e-3, "ok"),
                                                   ("b", 50, 2e-2, 1e-2, "failed")):
        rows += [_frow(problem, "iq:auto", "ok", auto, size=size),
                 _frow(problem, "iq:nsgs", "failed", 1.0, 1e-3, size=size),
                 _frow(problem, "siconos:NSGS", nsgs_status, nsgs, size=size),
                 _frow(problem, "siconos:PROX", "skipped", None, None, size=size)]
    assert friction_report.problems(rows) == ["friction:a", "friction:b"]
    ratio = friction_report.default_ratios(rows)
    assert ratio == {"friction:a": (0.25, True, True), "friction:b": (2.0, True, False)}
    times = friction_report.profile_times(rows)
    assert set(times) == {"iq:auto", "iq:nsgs", "siconos:NSGS"}  # PROX skipped: left out
    assert times["siconos:NSGS"] == [4e-3, math.inf] and times["iq:nsgs"] == [math.inf] * 2
    found = friction_report.targets(rows)

    def target(start):
        (hit,) = [(m, v) for t, m, v in found if t.startswith(f"friction: {start}")]
        return hit

    assert target("every FCLib") == ("2 of 2", "met")
    assert target("iq:auto time") == ("1 of 2 (slower: b)", "MISSED")
    assert target("geometric mean") == ("0.707", "MISSED by 2.4×")  # √(0.25 · 2) / 0.3
    assert target("Dolan–Moré")[0].startswith("fastest on 2 of 2")
    text = "\n".join(friction_report.markdown(rows))
    assert "| b | 50 |" in text and "2.00 (NSGS failed)" in text and "0.707" in text
    assert "iq:auto 2/2; iq:nsgs 0/0; siconos:NSGS 0/1." in text  # fastest on / solved
    assert friction_report.plot(rows, tmp_path / "p.png")
    assert (tmp_path / "p.png").read_bytes()[:4] == b"\x89PNG"
    assert not friction_report.plot([], tmp_path / "none.png")


def test_friction_suite_without_siconos_is_skipped(tmp_path):
    from benchmarks.friction import IQ_METHODS, run_friction

    rows = run_friction("quick", budget=0.0, max_repeats=1, siconos_python=sys.executable)
    if any(r["group"] == "peer" and r["status"] != "skipped" for r in rows):
        pytest.skip("siconos imports in this Python itself")
    mine = [r for r in rows if r["group"] == "impactqp"]
    assert [r["method"] for r in mine] == list(IQ_METHODS)
    assert all(r["status"] == "ok" and r["error"] <= 1e-8 and r["times"] for r in mine)
    peer = [r for r in rows if r["group"] == "peer"]
    assert len(peer) == 3 and all(r["status"] == "skipped" for r in peer)
    assert run_friction("smoke", budget=0.0, max_repeats=1) == []


@pytest.mark.skipif(not _siconos_here(), reason="python3-siconos not installed")
def test_friction_peer_is_judged_by_impactqp():
    from benchmarks.friction import run_friction

    rows = run_friction("quick", budget=0.0, max_repeats=1)
    peer = {r["method"]: r for r in rows if r["group"] == "peer"}
    assert set(peer) == {"siconos:NSGS", "siconos:NSN_AC", "siconos:PROX"}
    nsgs = peer["siconos:NSGS"]
    assert nsgs["status"] == "ok" and nsgs["error"] <= 1e-8 and "Siconos info 0" in nsgs["message"]
    for r in peer.values():  # ok exactly when impactqp's ABH error is within 1e-8
        assert (r["status"] == "ok") == (r["error"] <= 1e-8), r


def test_merge_replaces_only_friction_rows(tmp_path):
    from benchmarks.measure import row
    from benchmarks.runner import merge_records

    old = [row("random", 2, "iq:auto", "impactqp", status="ok", times=[1.0]),
           row("friction:gone", 3, "iq:auto", "impactqp", status="ok", times=[1.0]),
           row("friction-impact", 1, "iq:solve_friction", "impactqp", status="ok")]
    (tmp_path / "results.json").write_text(json.dumps({"meta": {"suite": "full"},
                                                       "records": old}))
    new = [row("friction:kept", 9, "iq:auto", "impactqp", status="ok", times=[2.0])]
    records, meta = merge_records(tmp_path / "results.json", new,
                                  {"suite": "friction", "seconds": 3.0})
    assert [r["family"] for r in records] == ["random", "friction:kept"]
    assert meta["suite"] == "full" and meta["refreshed"]["families"] == ["friction:kept"]


def test_siconos_server_stops_when_silent(tmp_path):
    from benchmarks import siconos_worker, simulation

    assert siconos_worker.ANSWER == simulation.ANSWER  # one protocol for both servers
    script = tmp_path / "silent.py"
    script.write_text("import sys, time\nsys.stdin.readline()\ntime.sleep(30)\n")
    server = simulation.SiconosServer(sys.executable, script, "--serve")
    with pytest.raises(TimeoutError, match="no answer within 0.5 s"):
        server.request({"x": 1}, timeout=0.5)
    assert not server.alive


def test_impactqp_runs_are_stopped_at_the_limit():
    import time

    import impactqp as iq
    from benchmarks.friction import first_run

    def slow(problem):
        time.sleep(30)

    def broken(problem):
        raise iq.CertificateError("no method certified it")

    p = iq.FrictionContactProblem([[1.0, 0, 0], [0, 2.0, 0], [0, 0, 2.0]], [-1.0, 2.0, 0.0],
                                  0.5)
    assert first_run(slow, p, limit=0.5) == ("stopped", 0.5, "")
    status, seconds, (message, best, attempts) = first_run(broken, p)
    assert status == "error" and "CertificateError: no method" in message and seconds < 5
    assert best is None and attempts == []  # raised without a best answer
    status, _, (r, u, route) = first_run(iq.solve_friction, p)
    # sliding (sticking would need r_t = −1, outside the cone): r_n = 1, r_t = −μ r_n
    assert status == "ok" and abs(r[0] - 1.0) < 1e-9 and abs(r[1] + 0.5) < 1e-9 and route


def test_friction_suite_alone_merges_into_earlier_results(tmp_path, monkeypatch, capsys):
    from benchmarks import friction, friction_impacts
    from benchmarks.__main__ import main
    from benchmarks.measure import row

    with pytest.raises(SystemExit) as exc:  # nothing to merge into
        main(["run", "--suite", "friction", "--merge", "--out", str(tmp_path / "none")])
    assert exc.value.code == 2 and "--merge needs" in capsys.readouterr().err
    monkeypatch.setitem(friction.PROBLEMS, "friction", ["LMGC-00046"])
    monkeypatch.setitem(friction_impacts.SIZES, "friction", ([1], (3, 0.01)))
    meta = {"suite": "full", "seconds": 9.0, "timing_budget_s": 0.3, "max_repeats": 500,
            "accurate_below": 1e-6}
    old = [row("random", 2, "iq:auto", "impactqp", status="ok", times=[1e-5], error=0.0),
           row("friction:Capsules", 286, "iq:auto", "impactqp", status="ok", times=[1.0])]
    (tmp_path / "results.json").write_text(json.dumps({"meta": meta, "records": old}))
    main(["run", "--suite", "friction", "--merge", "--out", str(tmp_path),
          "--siconos-python", "", "--no-progress"])
    assert "friction_profile.png" in capsys.readouterr().out
    data = json.loads((tmp_path / "results.json").read_text())
    families = {r["family"] for r in data["records"]}
    assert families == {"random", "friction:LMGC-00046", "friction-impact"}
    assert data["meta"]["suite"] == "full" and data["meta"]["refreshed"]["suite"] == "friction"
    text = (tmp_path / "summary.md").read_text()
    assert "## random" in text and "| LMGC-00046 | 9 |" in text and "## friction-impact" in text
    assert "Rows of friction-impact, friction:LMGC-00046 refreshed since by a `friction` run" \
        in text
    assert (tmp_path / "friction_profile.png").read_bytes()[:4] == b"\x89PNG"
