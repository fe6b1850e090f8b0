"""What derivatives cost beside the solve (issue 26's targets: JVP and VJP each ≤ 2× the
solve, a full n × n Jacobian ≤ (n + 1)× the solve, ``derivative_batch`` ≥ 0.5×
``solve_batch``'s throughput).

Two impacts of Moreau's law, compiled and warm: three balls (u⁻ = (1, 0, −½), ε = ½) and a
random impact with 10 contacts (n = 12). For each, the medians over alternating calls of
``iq.solve(problem, law)`` and of what a user calls after it, each time forming the
derivative anew as the issue counts it: ``r.derivative()`` alone (the law's local map: the
factor of G_AA, the cell's margin, the residual and condition of its solves), and
``r.derivative()`` followed by one JVP, by one VJP, or by the dense ∂u⁺/∂u⁻; the ratios
printed are those over the solve. Then the rows per second of ``iq.solve_batch`` and
``iq.derivative_batch`` (with JVP and VJP rows) on 3-ball rows, best of three, one thread.
Run: ``python -m benchmarks.derivatives [--rows N] [--repeats R]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import impactqp as iq

from .coulomb_overhead import alternating_medians

EPS = 0.5


def cases() -> dict[str, iq.ImpactProblem]:
    return {"3 balls": iq.newtons_cradle(3).with_u_minus([1.0, 0.0, -0.5]),
            "10 contacts": iq.random_impact(12, 10, seed=4)}


def single(problem: iq.ImpactProblem, repeats: int) -> dict[str, float]:
    """Median µs of the solve, of forming the derivative, and of forming it with a JVP, a
    VJP or the full Jacobian."""
    law = iq.Moreau(EPS)
    r = iq.solve(problem, law)
    t = np.random.default_rng(0).normal(size=problem.n_dof)
    solve, derive, jvp, vjp, jac = alternating_medians([
        lambda: iq.solve(problem, law), r.derivative,
        lambda: r.derivative().jvp(u_minus=t), lambda: r.derivative().vjp(u_plus=t),
        lambda: r.derivative().jacobian()], repeats)
    return {"solve": solve, "derivative": derive, "jvp": jvp, "vjp": vjp, "jacobian": jac,
            "n": problem.n_dof, "status": r.derivative().status}


def batch(rows: int, n_jobs: int = 1) -> dict[str, float]:
    """Rows per second of solve_batch and derivative_batch (JVP and VJP rows) on 3 balls."""
    p = iq.newtons_cradle(3)
    rng = np.random.default_rng(1)
    U = rng.normal(size=(rows, 3))
    dU, Ub = rng.normal(size=(rows, 3)), rng.normal(size=(rows, 3))
    law = iq.Moreau(EPS)
    iq.solve_batch(p, law, U[:100])
    iq.derivative_batch(p, law, U[:100], jvp=dU[:100], vjp=Ub[:100])  # compiled, warm
    best = {"solve_batch": np.inf, "derivative_batch": np.inf}
    for _ in range(3):
        start = time.perf_counter()
        iq.solve_batch(p, law, U, n_jobs=n_jobs)
        best["solve_batch"] = min(best["solve_batch"], time.perf_counter() - start)
        start = time.perf_counter()
        iq.derivative_batch(p, law, U, jvp=dU, vjp=Ub, n_jobs=n_jobs)
        best["derivative_batch"] = min(best["derivative_batch"], time.perf_counter() - start)
    return {k: rows / v for k, v in best.items()}


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.derivatives")
    parser.add_argument("--rows", type=int, default=10**6)
    parser.add_argument("--repeats", type=int, default=2000)
    args = parser.parse_args(argv)
    for label, problem in cases().items():
        m = single(problem, args.repeats)
        s = m["solve"]
        print(f"{label} (n = {m['n']}, {m['status']}): solve {s:.1f} µs; derivative "
              f"{m['derivative']:.1f} µs ({m['derivative'] / s:.2f}×); derivative + JVP "
              f"{m['jvp']:.1f} µs ({m['jvp'] / s:.2f}×, target ≤ 2×); derivative + VJP "
              f"{m['vjp']:.1f} µs ({m['vjp'] / s:.2f}×, target ≤ 2×); derivative + "
              f"jacobian {m['jacobian']:.1f} µs ({m['jacobian'] / s:.2f}×, target ≤ "
              f"{m['n'] + 1}×)")
    b = batch(args.rows)
    print(f"{args.rows} 3-ball rows: solve_batch {b['solve_batch']:.3g} rows/s, "
          f"derivative_batch {b['derivative_batch']:.3g} rows/s "
          f"({b['derivative_batch'] / b['solve_batch']:.2f}×, target ≥ 0.5×)")


if __name__ == "__main__":
    main()
