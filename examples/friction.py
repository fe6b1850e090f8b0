"""Frictional impacts: stick, slip and an FCLib problem
====================================================

Frictional impacts: a sphere hitting the floor obliquely under Coulomb's law, and an FCLib
problem solved with its certificate.

Run it as::

    python examples/friction.py              # prints the tables, writes nothing
    python examples/friction.py --out DIR    # also writes the sphere's problem file into DIR

A solid sphere (1 kg, radius 0.1 m, spinning not at all) lands at u⁻ = (vx, vy, ω) =
(1, −2, 0) m/s with Newton's e = 0.5 in the normal. For each μ, iq.Coulomb's u⁺ is printed
beside the closed form of docs/theory.md §16: the normal impulse is P_n = m(1 + e)|vy⁻|
and the impulse that stops the contact point's sliding is P_stick = m_t·s⁻, with s = vx + Rω
and m_t = 2/7 m; the point sticks when P_stick ≤ μP_n, else it slides with P_t = μP_n.
Then one FCLib file of the repository's test data (nine contacts in space) is solved by
iq.solve_friction and its certificate printed.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import impactqp as iq

MASS, RADIUS, RESTITUTION = 1.0, 0.1, 0.5
U_MINUS = np.array([1.0, -2.0, 0.0])
FCLIB = Path(__file__).resolve().parents[1] / "tests" / "data" / "fclib" / \
    "LMGC_GlobalFrictionContactProblem00046.hdf5"


def closed_form(mu: float) -> tuple[str, np.ndarray]:
    """The regime and u⁺ of the sphere by hand (stick or slip)."""
    vx, vy, omega = U_MINUS
    inertia = 0.4 * MASS * RADIUS ** 2
    normal = MASS * (1.0 + RESTITUTION) * -vy
    slide = vx + RADIUS * omega
    tangential_mass = 1.0 / (1.0 / MASS + RADIUS ** 2 / inertia)
    stick = tangential_mass * abs(slide)
    regime = "stick" if stick <= mu * normal else "slip"
    tangent = -np.sign(slide) * min(stick, mu * normal)
    return regime, np.array([vx + tangent / MASS, vy + normal / MASS,
                             omega + RADIUS * tangent / inertia])


def sphere_table(problem: iq.ImpactProblem) -> None:
    print(f"sphere on the floor, u⁻ = {U_MINUS.tolist()}, e = {RESTITUTION}")
    print(f"{'μ':>5}  {'regime':<6}  {'u⁺ (iq.Coulomb)':<30}  {'u⁺ (closed form)':<30}  "
          "difference  certificate  u⁺ ∈ S")
    for mu in (0.0, 0.05, 0.3):
        result = iq.solve(problem, iq.Coulomb(mu, RESTITUTION))
        regime, expected = closed_form(mu)
        shown = "(" + ", ".join(f"{x:+.4f}" for x in result.u_plus) + ")"
        by_hand = "(" + ", ".join(f"{x:+.4f}" for x in expected) + ")"
        gap = float(np.max(np.abs(result.u_plus - expected)))
        print(f"{mu:>5}  {regime:<6}  {shown:<30}  {by_hand:<30}  {gap:.1e}     "
              f"{'ok' if result.certificate.ok else 'FAILED':<11}  "
              f"{'yes' if result.admissible else 'no'}")


def fclib_table() -> None:
    problem = iq.load_fclib(FCLIB)
    found = iq.solve_friction(problem)
    cert = found.certificate
    print(f"\nFCLib {FCLIB.name}: {problem.n_contacts} contacts, d = {problem.contact_dim}")
    print(f"solved by {found.backend} in {found.solve_time:.3g} s, certificate "
          f"{'ok' if cert.ok else 'FAILED'} at tol {cert.tol:.0e}")
    for name, value in {**cert.values, **cert.reported}.items():
        print(f"  {name:<16} {value:.2e}")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, help="folder for the sphere's problem file "
                                                 "(default: write nothing)")
    args = parser.parse_args(argv)
    problem = iq.friction.sphere_on_plane(MASS, RADIUS, U_MINUS)
    sphere_table(problem)
    fclib_table()
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        law = iq.Coulomb(0.3, RESTITUTION)
        iq.save_problem(problem, args.out / "sphere_on_plane.toml", law="coulomb",
                        coefficients=law.coefficients)
        print(f"problem file written to {args.out}")


if __name__ == "__main__":
    main()
