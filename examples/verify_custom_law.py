"""Verify an impact law of your own with impactqp.verify_law.

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

from dataclasses import dataclass

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
@dataclass(frozen=True)
class ElasticCertificate(iq.ResidualChecks):
    """Recomputed checks of an elastic answer, dimensionless (velocities against ‖u⁻‖)."""

    momentum: float  # ‖u⁺ − u⁻ − M⁻¹WΛ‖ / ‖u⁻‖: the impact equation
    impulse_sign: float  # largest violation of Λ ≥ 0
    kinematic: float  # largest violation of γ⁺ ≥ 0
    energy_balance: float  # |‖u⁺‖² − ‖u⁻‖²| / ‖u⁻‖²: elastic
    tol: float

    @property
    def residuals(self) -> dict[str, float]:
        return {"momentum": self.momentum, "impulse_sign": self.impulse_sign,
                "kinematic": self.kinematic, "energy_balance": self.energy_balance}


def elastic_residuals(M: np.ndarray, W: np.ndarray, u_minus: np.ndarray, u_plus: np.ndarray,
                      impulses: np.ndarray) -> dict[str, float]:
    def norm(u: np.ndarray) -> float:
        return float(np.sqrt(u @ M @ u))

    V = max(norm(u_minus), 1e-300)
    s = np.sqrt(np.einsum("ij,ij->j", W, np.linalg.solve(M, W)))
    return {
        "momentum": norm(u_plus - u_minus - np.linalg.solve(M, W @ impulses)) / V,
        "impulse_sign": float(max(0.0, -np.min(impulses * s, initial=0.0) / V)),
        "kinematic": float(max(0.0, -np.min((W.T @ u_plus) / s, initial=0.0) / V)),
        "energy_balance": abs(norm(u_plus) ** 2 - norm(u_minus) ** 2) / V**2,
    }


class SequentialCollisions(iq.ImpactLaw):
    """Single elastic collisions, the most strongly approaching contact first."""

    name = "sequential"
    title = "sequential elastic collisions"
    forms = ()  # closed form: no program, iq.solve calls closed_form
    closed_form_backend = "collisions"

    def closed_form(self, problem: iq.ImpactProblem) -> iq.Answer:
        return iq.Answer(*collisions(dense(problem.M), dense(problem.W), problem.u_minus))

    def closed_form_rows(self, problem, U_minus):
        """(U⁺, Λ) for every row of U_minus (used by iq.solve_batch)."""
        M, W = dense(problem.M), dense(problem.W)
        answers = [collisions(M, W, u) for u in U_minus]
        return np.array([a[0] for a in answers]), np.array([a[1] for a in answers])

    def residuals(self, structure, U_minus, U_plus, impulses):
        """One impact (1-D arrays) or rows of impacts (used by iq.solve_batch)."""
        M, W = dense(structure.M), dense(structure.W)
        if np.ndim(U_minus) == 1:
            return elastic_residuals(M, W, U_minus, U_plus, impulses)
        rows = [elastic_residuals(M, W, *row) for row in zip(U_minus, U_plus, impulses)]
        return {key: np.array([r[key] for r in rows]) for key in rows[0]}

    def certificate(self, problem, answer, tol):
        res = elastic_residuals(dense(problem.M), dense(problem.W), problem.u_minus,
                                answer.u_plus, answer.impulses)
        return ElasticCertificate(**res, tol=tol)


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
