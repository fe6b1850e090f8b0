"""A forked copy of a process that has used Clarabel's thread pool still solves: Clarabel runs
on one thread there (impactqp.qp.backends.clarabel_), where it used to wait for ever for the
pool's threads, which a fork does not copy. This was the benchmark's stall on KaplasTower:
its timing copy of each impactqp row is forked (benchmarks.friction.first_run).

The scene runs in a fresh interpreter, so that this test process never holds the pool."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

SCENE = r"""
import json, multiprocessing, os, types
import clarabel
import numpy as np
import scipy.sparse as sp
from impactqp.qp.backends import clarabel_
from benchmarks.friction import first_run

def threads():
    return len(os.listdir(f"/proc/{os.getpid()}/task"))

n = 200  # a dense QP this size is factorized on the pool
rng = np.random.default_rng(0)
G = rng.standard_normal((n, n))
P, c = G @ G.T / n + np.eye(n), rng.standard_normal(n)

def solve():
    sol, _ = clarabel_.run(P, c, -sp.eye(n, format="csc"), np.zeros(n),
                           [clarabel.NonnegativeConeT(n)], 1e-8)
    return np.array(sol.x)

def child(conn):
    conn.send((clarabel_.settings(1e-8).max_threads, solve().tolist()))

before = threads()
x = solve()
out = {"pool": threads() - before, "parent_threads_setting": clarabel_.settings(1e-8).max_threads}
ctx = multiprocessing.get_context("fork")
receive, send = ctx.Pipe(duplex=False)
proc = ctx.Process(target=child, args=(send,), daemon=True)
proc.start()
send.close()
if receive.poll(30):
    setting, y = receive.recv()
    out.update(child_threads_setting=setting, child_same=bool(np.array_equal(x, y)))
else:
    out.update(child_threads_setting=None, child_same=None)
proc.kill()
proc.join()
status, seconds, answer = first_run(
    lambda _: types.SimpleNamespace(r=solve(), u=None, backend="clarabel"), None, 30.0)
out.update(first_run=status, first_run_same=status == "ok" and bool(np.array_equal(x, answer[0])))
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def scene() -> dict:
    done = subprocess.run([sys.executable, "-c", SCENE], cwd=ROOT, capture_output=True,
                          text=True, timeout=300, env={**os.environ,
                                                       "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="counts threads in /proc")
def test_the_parent_started_clarabels_pool(scene: dict) -> None:
    # the premise of the other tests: without the pool's threads there is no hazard to test
    assert scene["pool"] > 0
    assert scene["parent_threads_setting"] == 0  # the parent keeps Clarabel's own choice


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="counts threads in /proc")
def test_a_forked_child_solves_on_one_thread_with_the_same_answer(scene: dict) -> None:
    assert scene["child_threads_setting"] == 1, "the forked child did not answer in 30 s"
    assert scene["child_same"] is True


@pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="counts threads in /proc")
def test_the_benchmarks_forked_timing_copy_finishes(scene: dict) -> None:
    assert scene["first_run"] == "ok"
    assert scene["first_run_same"] is True
