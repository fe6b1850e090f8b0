"""Verifying a law of your own
===========================

Verify an impact law of your own with impactqp.verify_law.

The law here resolves a simultaneous impact as a sequence of single elastic collisions: while
some contact approaches (γᵢ < 0), the most strongly approaching one bounces (Newton's law
with e = 1 at that contact alone). It is written twice:

1. as a plain callable ``law(problem) -> u⁺`` (all verify_law needs), and
2. as an ``impactqp.ImpactLaw`` subclass, so that ``iq.solve`` runs it and certifies its
   answer like any built-in law.

For equal balls it is the sector law (u⁺ = sort(u⁻)) and passes every check; for the
masses (1, 2, 1) the outcome depends on which collision comes first, and verify_law finds
pairs of nearby u⁻ whose answers lie far apart (the law is not non-expansive, hence not
maximal monotone).

Run: python examples/verify_custom_law.py
"""

from __future__ import annotations

import numpy as np

import impactqp as iq

MAX_COLLISIONS = 1000


def dense(A) -> np.ndarray:
    return A.toarray() if hasattr(A, "toarray") else np.asarray(A, dtype=float)


def collisions(M: np.ndarray, W: np.ndarray, u_minus: np.ndarray) -> tuple[np.ndarray,
                                                                            np.ndarray]:
    """u⁺ and the accumulated impulses Λ of the sequence of single elastic collisions."""
    Minv_W = np.linalg.solve(M, W)
    G_diag = np.einsum("ij,ij->j", W, Minv_W)
    u, impulses = u_minus.astype(float).copy(), np.zeros(W.shape[1])
    if not np.any(u):  # nothing moves: nothing collides
        return u, impulses
    scale = np.sqrt(u_minus @ M @ u_minus) * np.sqrt(G_diag)  # |γᵢ| ≤ sᵢ‖u‖
    for _ in range(MAX_COLLISIONS):
        gamma = W.T @ u
        i = int(np.argmin(gamma / scale))
        if gamma[i] >= -1e-13 * scale[i]:
            return u, impulses
        bounce = -2.0 * gamma[i] / G_diag[i]  # e = 1: γᵢ ↦ −γᵢ
        u += Minv_W[:, i] * bounce
        impulses[i] += bounce
    raise iq.NoSolutionError(f"more than {MAX_COLLISIONS} collisions")


# --------------------------------------------------------------------- 1. a plain callable
def sequential_law(problem: iq.ImpactProblem) -> np.ndarray:
    """The law as a function: u⁺ for the problem's u⁻."""
    u_plus, _ = collisions(dense(problem.M), dense(problem.W), problem.u_minus)
    return u_plus


# --------------------------------------------------------------------- 2. an ImpactLaw
class SequentialCollisions(iq.ImpactLaw):
    """Single elastic collisions, the most strongly approaching contact first.

    A closed form is all a law needs: iq.solve certifies its (u⁺, Λ) by the impact
    equation and Λ ≥ 0, iq.solve_batch runs it row by row, and ``result.admissible`` says
    whether u⁺ lies in S. (Returning u⁺ alone works too: Λ is then recovered.)"""

    def closed_form(self, problem: iq.ImpactProblem) -> tuple[np.ndarray, np.ndarray]:
        return collisions(dense(problem.M), dense(problem.W), problem.u_minus)


def main() -> None:
    cradle = iq.newtons_cradle(3)
    r = iq.solve(cradle, SequentialCollisions())
    print(f"iq.solve on the 3-ball cradle: u⁺ = {np.round(r.u_plus, 6).tolist()}, "
          f"certificate {r.certificate.summary()}\n")

    unequal = iq.chain([1.0, 2.0, 1.0], [1.0, 0.0, 0.0])
    for title, problem in (("equal masses (1, 1, 1)", cradle),
                           ("masses (1, 2, 1)", unequal)):
        for kind, law in (("callable", sequential_law),
                          ("ImpactLaw", lambda q: iq.solve(q, SequentialCollisions()))):
            report = iq.verify_law(law, problem, samples=300, seed=0)
            print(f"{title}, {kind}: {report.summary()}")
        if report.worst is not None:
            ce = report.worst
            print(f"worst counterexample ({ce.condition}, amount {ce.amount:.3g}):")
            print(f"  u⁻ = {np.round(ce.u_minus, 4).tolist()}")
            print(f"  u⁺ = {np.round(ce.u_plus, 4).tolist()}")


if __name__ == "__main__":
    main()
