"""What ``iq.solve`` with ``iq.Coulomb`` costs over ``iq.solve_friction`` on the same local
problem (issue 25: the law poses its local problem once, solves it through the registry and
builds one certificate; target ≤ 1.5×).

Two impacts: a sphere on a plane (one contact, ``iq.friction.sphere_on_plane``) and three
spheres in a row on a plane (five contacts,
:func:`benchmarks.friction_impacts.spheres_in_a_row`). For each, the medians over repeated
calls of ``iq.solve(problem, iq.Coulomb(μ))`` and of
``iq.solve_friction(local)`` on the law's own local problem in contact units
(``law.local_problem(problem)[0]``, posed untimed), of the law's certificate alone (one
compiled pass) and of its numpy reference (``law.reference_residuals``, the same residuals).
The calls alternate, so that a machine shared with other work slows them alike. Run:
``python -m benchmarks.coulomb_overhead``.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable

import impactqp as iq
from impactqp.laws.base import Answer

from .friction_impacts import spheres_in_a_row

MU = 0.3
REPEATS = 3000


def alternating_medians(calls: list[Callable[[], object]], repeats: int = REPEATS
                        ) -> list[float]:
    """Median µs of each call, the calls alternating (one warm-up call each first)."""
    for call in calls:
        call()
    times: list[list[float]] = [[] for _ in calls]
    for _ in range(repeats):
        for spent, call in zip(times, calls, strict=True):
            start = time.perf_counter()
            call()
            spent.append(time.perf_counter() - start)
    return [statistics.median(spent) * 1e6 for spent in times]


def cases() -> dict[str, iq.ImpactProblem]:
    five = spheres_in_a_row(3)  # 2·3 − 1 = 5 contacts
    return {"sphere on a plane": iq.friction.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0]),
            "5 contacts": iq.ImpactProblem(five.M, five.H, five.v_minus, contact_dim=3)}


def main() -> None:
    for label, problem in cases().items():
        law = iq.Coulomb(MU)
        local = law.local_problem(problem)[0]
        result = iq.solve(problem, law)
        answer = Answer(result.u_plus, result.impulses, None)
        law_solve, friction, certificate, reference = alternating_medians([
            lambda p=problem, law=law: iq.solve(p, law),
            lambda local=local: iq.solve_friction(local),
            lambda p=problem, law=law, a=answer, tol=result.certificate.tol:
                law.certificate(p, a, tol),
            lambda p=problem, law=law, a=answer:
                law.reference_residuals(p.structure, p.u_minus, a.u_plus, a.impulses)])
        print(f"{label}: iq.solve(Coulomb) {law_solve:.1f} µs, solve_friction {friction:.1f} µs, "
              f"ratio {law_solve / friction:.2f}; the law's certificate alone "
              f"{certificate:.1f} µs, its numpy reference {reference:.1f} µs "
              f"(backend {result.backend!r})")


if __name__ == "__main__":
    main()
