"""A small dense problem is built and solved in the calling thread, with the operators of
the Cholesky factor of M (B = L⁻¹W, M⁻¹W = L⁻ᵀB, G = BᵀB; docs/theory.md §1) right to
round-off.

OpenBLAS runs LAPACK's ``trtrs`` on its thread pool at every size: on a loaded machine the
caller then waits milliseconds for a worker to be scheduled, and the worker spinning after
the job slows the caller's next BLAS calls. The structure solves with BLAS's ``trsm``, which
OpenBLAS keeps in the calling thread below 1024 entries of the right-hand side, in blocks of
columns that size for a small problem. The last test watches the thread pools themselves: a
worker that took a job went to sleep again afterwards (a voluntary context switch in /proc).
"""

import os
import sys
import time
from functools import partial

import numpy as np
import pytest
from scipy.linalg import lapack

import impactqp as iq
from impactqp.base.cholesky import SMALL, cholesky_solve

EPS = np.finfo(float).eps


def _spd(rng, n, cond):
    """A symmetric positive definite matrix of condition number ``cond``, eigenvectors random."""
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    M = (Q * np.geomspace(1.0, 1.0 / cond, n)) @ Q.T
    return (M + M.T) / 2


@pytest.mark.parametrize("cond", [1.0, 1e6, 1e12])
@pytest.mark.parametrize("n, m", [(2, 1), (3, 2), (20, 10), (30, 34), (40, 30), (64, 64),
                                  (12, 90), (70, 40)])
def test_operators_of_the_cholesky_factor(n, m, cond):
    """B = L⁻¹W, M⁻¹W and G against their definitions (backward errors, independent of the
    order of the arithmetic) and against LAPACK's trtrs/potrs to round-off, W given in either
    memory order."""
    rng = np.random.default_rng(n * 1000 + m)
    M = _spd(rng, n, cond)
    for W in (rng.standard_normal((n, m)), np.asfortranarray(rng.standard_normal((n, m)))):
        st = iq.ImpactProblem(M, W, np.zeros(n)).structure
        L = st.cholesky_factor
        B, X, G = st.scaled_W, st.Minv_W, st.delassus
        assert B.shape == X.shape == (n, m) and G.shape == (m, m)
        # backward errors: L B = W, M X = W, each to a few ulps of the products' size
        tol = 8 * n * EPS
        assert np.abs(L @ B - W).max() <= tol * np.abs(L).max() * np.abs(B).max() * n
        assert np.abs(M @ X - W).max() <= tol * np.abs(M).max() * np.abs(X).max() * n
        # G = BᵀB = WᵀM⁻¹W, the second from X
        assert np.abs(G - W.T @ X).max() <= 1e-10 * cond * np.abs(G).max()
        assert np.array_equal(st.delassus_diagonal, np.einsum("ij,ij->j", B, B))
        # solve_mass on W's columns is the same two solves; on one column, LAPACK's potrs
        assert np.array_equal(st.solve_mass(W), X)
        assert np.abs(st.solve_mass(W[:, 0]) - X[:, 0]).max() <= 1e-12 * np.abs(X).max()
        # LAPACK's triangular solves (what the structure called before): round-off apart
        B_ref = lapack.dtrtrs(L, W, lower=1)[0]
        X_ref = lapack.dpotrs(L, W, lower=1)[0]
        forward = 8 * n * EPS * np.sqrt(cond)  # cond(L) = √cond(M)
        assert np.abs(B - B_ref).max() <= forward * np.abs(B_ref).max()
        assert np.abs(X - X_ref).max() <= forward * np.sqrt(cond) * np.abs(X_ref).max()


@pytest.mark.parametrize("n", [1, 7, 33, SMALL, SMALL + 1])
def test_cholesky_solve_every_width(n):
    """L⁻¹X and L⁻ᵀX for every column count up to SMALL + 1 (each way the columns split
    into blocks, a last block of one column included) against LAPACK's trtrs, to
    round-off; X is left as it was."""
    rng = np.random.default_rng(n)
    M = _spd(rng, n, 1e4)
    L = lapack.dpotrf(M, lower=1, clean=1)[0]
    for m in range(1, SMALL + 2):
        X = rng.standard_normal((n, m))
        kept = X.copy()
        for transpose in (False, True):
            Y = cholesky_solve(L, X, transpose)
            ref = lapack.dtrtrs(L, X, lower=1, trans=int(transpose))[0]
            assert np.abs(Y - ref).max() <= 1e-12 * np.abs(ref).max(), (m, transpose)
        assert np.array_equal(X, kept)


def test_solve_with_the_structure_matches_a_dense_kkt_solve():
    """Moreau's law on a small ill-conditioned M: u⁺ equals an independent solve of its
    optimality conditions on the active contacts (the answer uses M⁻¹W of the structure)."""
    rng = np.random.default_rng(7)
    n, m = 20, 10
    M = _spd(rng, n, 1e8)
    W = rng.standard_normal((n, m))
    u = rng.standard_normal(n)
    r = iq.moreau(iq.ImpactProblem(M, W, u), 0.0)
    assert r.certificate.ok
    active = r.impulses > 0
    Wa = W[:, active]
    # u⁺ = u⁻ + M⁻¹WₐΛₐ with Wₐᵀu⁺ = 0 (ε = 0): Λₐ = −(WₐᵀM⁻¹Wₐ)⁻¹Wₐᵀu⁻
    Y = np.linalg.solve(M, Wa)
    lam = -np.linalg.solve(Wa.T @ Y, Wa.T @ u)
    u_plus = u + Y @ lam
    scale = np.sqrt(u @ M @ u)
    assert np.sqrt((r.u_plus - u_plus) @ M @ (r.u_plus - u_plus)) <= 1e-8 * scale


@pytest.mark.parametrize("M, smallest", [
    (np.array([[1.0, 2.0], [2.0, 1.0]]), -1.0),
    (np.diag([1.0, 0.0, 2.0]), 0.0),
    (np.diag([3.0, 2.0, -4.0]), -4.0),
])
def test_mass_not_positive_definite(M, smallest):
    """A dense M that is not positive definite is refused by name, its smallest eigenvalue
    in the message."""
    with pytest.raises(iq.errors.MassMatrixError,
                       match=f"M must be positive definite; its smallest eigenvalue is "
                             f"{smallest:.3g}"):
        iq.ImpactProblem(M, np.ones((M.shape[0], 2)), np.zeros(M.shape[0]))


# --- the thread pools ------------------------------------------------------------------

def _workers() -> dict[int, tuple[str, int]]:
    """The process's other threads: state letter and voluntary context switches."""
    out = {}
    for name in os.listdir("/proc/self/task"):
        tid = int(name)
        if tid == os.getpid():
            continue
        try:
            with open(f"/proc/self/task/{tid}/status") as f:
                fields = dict(line.split(":", 1) for line in f if ":" in line)
        except FileNotFoundError:  # the thread ended
            continue
        out[tid] = (fields["State"].split()[0], int(fields["voluntary_ctxt_switches"]))
    return out


def _woken(call, *args, watched=None, times=1) -> set[int]:
    """The threads (among ``watched``) that took a job during ``times`` calls
    ``call(*args)``: each, asleep before, went to sleep again after, one voluntary switch
    more."""
    def settled():
        deadline = time.monotonic() + 10.0
        while True:  # a pool's worker spins (running) a while after a job, then sleeps
            now = _workers()
            busy = [t for t, (s, _) in now.items() if s == "R" and (watched is None
                                                                    or t in watched)]
            if not busy or time.monotonic() > deadline:
                return now
            time.sleep(0.02)
    before = settled()
    for _ in range(times):
        call(*args)
    after = settled()
    return {t for t, (_, c) in after.items() if t in before and c != before[t][1]
            and (watched is None or t in watched)}


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/task")
def test_small_dense_problems_stay_in_the_calling_thread():
    """Building a dense problem of up to SMALL = 64 degrees of freedom and columns of W and
    its first Moreau, Newton and Frémond solves and derivative wake no BLAS worker, neither
    scipy's pool nor numpy's (40 × 30 and 64 × 64 solve W in blocks)."""
    rng = np.random.default_rng(0)
    L = np.linalg.cholesky(_spd(rng, 8, 10.0))
    W = rng.standard_normal((8, 4))
    big = rng.standard_normal((400, 400))
    # the pools, found by calls that use them: LAPACK's trtrs (scipy's OpenBLAS threads it
    # at any size) and a 400 × 400 product (numpy's)
    pools = _woken(partial(lapack.dtrtrs, lower=1), L, W) | _woken(np.matmul, big, big)
    if not pools:
        pytest.skip("no BLAS thread pool to watch (one thread, or a BLAS that runs these "
                    "calls in the caller)")
    problems = []
    for n, m in ((20, 10), (40, 30), (SMALL, SMALL)):
        p = iq.random_impact(n, m, seed=3)
        problems.append((np.array(p.structure.M), np.array(p.structure.W), p.u_minus.copy()))
    flows = {
        "build": lambda M, W, u: iq.ImpactProblem(M, W, u),
        "moreau": lambda M, W, u: iq.moreau(iq.ImpactProblem(M, W, u), 0.5),
        "newton": lambda M, W, u: iq.newton(iq.ImpactProblem(M, W, u), 0.5),
        "fremond": lambda M, W, u: iq.fremond(iq.ImpactProblem(M, W, u),
                                              0.2 * np.eye(W.shape[1])),
        "derivative": lambda M, W, u: iq.derivative(iq.ImpactProblem(M, W, u),
                                                    iq.Moreau(0.5)),
    }
    for M, W, u in problems:
        for name, flow in flows.items():
            flow(M, W, u)  # compiled (or its first calls interpreted) before it is watched
            woken = _woken(flow, M, W, u, watched=pools, times=3)
            assert not woken, f"{name} of a {W.shape} problem woke BLAS workers {woken}"
