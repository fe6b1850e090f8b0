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


def random_case(rng: np.random.Generator) -> tuple[iq.ImpactProblem, iq.ImpactLaw]:
    """An impact of the issue's random family: n ≤ 30 degrees of freedom, masses spread
    over 1e-3…1e3, a random W and u⁻, and Moreau's, Newton's or Frémond's law with
    coefficients in [0, 1]."""
    n = int(rng.integers(2, 31))
    m = int(rng.integers(1, n + 1))
    A = rng.normal(size=(n, n)) * 0.1
    scale = np.diag(10.0 ** rng.uniform(-1.5, 1.5, n))
    M = scale @ (np.eye(n) + A @ A.T) @ scale  # masses over about 1e-3…1e3
    p = iq.ImpactProblem(M, rng.normal(size=(n, m)), rng.normal(size=n))
    kind = int(rng.integers(3))
    if kind == 0:
        return p, iq.Moreau(float(rng.uniform()))
    if kind == 1:
        return p, iq.Newton(rng.uniform(size=m))
    return p, iq.Fremond(np.diag(rng.uniform(size=m)))


def agreement(problems: int, seed: int = 0) -> dict[str, int]:
    """Over ``problems`` random impacts: how many derivatives are smooth, how many of those
    agree with central differences of ``iq.solve`` to 1e-7 relative (a step of a quarter of
    the cell's certified margin, along a random u⁻ direction), and how many disagree while
    reported smooth (the target: none)."""
    rng = np.random.default_rng(seed)
    out = {"problems": problems, "smooth": 0, "agree": 0, "disagree": 0, "other": 0}
    for _ in range(problems):
        p, law = random_case(rng)
        d = iq.solve(p, law).derivative()
        if d.status != "smooth" or not d.certificate.ok:
            out["other"] += 1
            continue
        out["smooth"] += 1
        u = p.u_minus
        du = rng.normal(size=u.size)
        du *= np.linalg.norm(u) / np.linalg.norm(du)
        h = 0.25 * min(d.certificate.margin, 1.0)
        fd = (iq.solve(p.with_u_minus(u + h * du), law).u_plus
              - iq.solve(p.with_u_minus(u - h * du), law).u_plus) / (2 * h)
        jvp = d.jvp(u_minus=du).u_plus
        error = np.linalg.norm(jvp - fd) / max(np.linalg.norm(fd), np.linalg.norm(u))
        out["agree" if error <= 1e-7 else "disagree"] += 1
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.derivatives")
    parser.add_argument("--rows", type=int, default=10**6)
    parser.add_argument("--repeats", type=int, default=2000)
    parser.add_argument("--problems", type=int, default=500,
                        help="random impacts checked against central differences")
    args = parser.parse_args(argv)
    a = agreement(args.problems)
    print(f"{a['problems']} random impacts (n ≤ 30, masses 1e-3…1e3, Moreau/Newton/Frémond): "
          f"{a['smooth']} smooth, of which {a['agree']} agree with central differences to "
          f"1e-7 and {a['disagree']} disagree (target: 0); {a['other']} kinks or uncertified")
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
