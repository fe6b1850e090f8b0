"""Newton's cradle: Moreau's law and the sector law
================================================

Newton's cradle with three balls: solve it with Moreau's law (ε = 0 and ε = 1) and with
the sector law, verify each answer against the admissible set S, classify it, print a table.

Run: python examples/cradle.py
"""

from __future__ import annotations

import impactqp as iq


def table(head: list[str], rows: list[list[str]]) -> str:
    """Columns padded to their widest cell."""
    widths = [max(len(str(cell)) for cell in column) for column in zip(head, *rows)]
    lines = [head, ["-" * w for w in widths], *rows]
    return "\n".join("  ".join(str(c).ljust(w) for c, w in zip(line, widths)).rstrip()
                     for line in lines)


def vector(x) -> str:
    return "(" + ", ".join(f"{v:+.3f}" for v in x) + ")"


def main() -> None:
    p = iq.newtons_cradle(n_balls=3, v=1.0)  # ball 1 at v = 1 hits two resting balls
    S = p.admissible_set()
    laws = {"Moreau ε = 0": iq.Moreau(0.0), "Moreau ε = 1": iq.Moreau(1.0),
            "sector law": iq.SectorLaw()}
    rows = []
    for name, law in laws.items():
        r = iq.solve(p, law)  # certified: r.certificate.ok is always True here
        membership = S.contains(r.u_plus)  # the exact test u⁺ ∈ S
        c = iq.classify(p, r.u_plus)
        rows.append([name, vector(r.u_plus), vector(r.impulses),
                     f"{p.kinetic_energy(r.u_plus):.3f}", f"{c.alpha_deg:.1f}",
                     f"{c.dissipation:.2f}", "yes" if membership else "no",
                     "ok" if r.certificate.ok else "FAILED", r.backend])
    print(f"3-ball Newton's cradle, u⁻ = {vector(p.u_minus)}, T⁻ = {p.kinetic_energy():.3f}")
    print(table(["law", "u⁺", "Λ", "T⁺", "α [°]", "dissipation ε", "u⁺ ∈ S", "certificate",
                 "backend"], rows))


if __name__ == "__main__":
    main()
