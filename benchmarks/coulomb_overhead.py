"""What ``iq.solve`` with ``iq.Coulomb`` costs over ``iq.solve_friction`` on the same local
problem (issue 25: the law poses its local problem once, solves it through the registry and
builds one certificate; target ≤ 1.5×).

Two impacts: a sphere on a plane (one contact, ``iq.sphere_on_plane``) and three spheres in a
row on a plane (five contacts, :func:`benchmarks.friction_impacts.spheres_in_a_row`). For each,
the median over repeated calls of ``iq.solve(problem, iq.Coulomb(μ))`` and of
``iq.solve_friction(local)`` on the law's own local problem in contact units
(``law.local_problem(problem)[0]``, posed untimed). Run: ``python -m benchmarks.coulomb_overhead``.
"""

from __future__ import annotations

import impactqp as iq

from .friction_impacts import spheres_in_a_row
from .friction_steps import per_step

MU = 0.3
REPEATS = 2000


def cases() -> dict[str, iq.ImpactProblem]:
    five = spheres_in_a_row(3)  # 2·3 − 1 = 5 contacts
    return {"sphere on a plane": iq.sphere_on_plane(1.0, 0.1, [1.0, -2.0, 0.0]),
            "5 contacts": iq.ImpactProblem(five.M, five.H, five.v_minus, contact_dim=3)}


def main() -> None:
    for label, problem in cases().items():
        law = iq.Coulomb(MU)
        local = law.local_problem(problem)[0]
        a = per_step(lambda p=problem, law=law: iq.solve(p, law), 1, REPEATS)
        b = per_step(lambda local=local: iq.solve_friction(local), 1, REPEATS)
        backend = iq.solve(problem, law).backend
        print(f"{label}: iq.solve(Coulomb) {a:.1f} µs, solve_friction {b:.1f} µs (medians), "
              f"ratio {a / b:.2f} (backend {backend!r})")


if __name__ == "__main__":
    main()
