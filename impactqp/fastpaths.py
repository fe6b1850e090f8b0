"""Exact fast paths that bypass the general QP machinery (Moreau's law and small LCPs).

* ``"isotonic"`` – 1-D chains (§5): Moreau's projection is weighted isotonic regression,
  O(N) (:mod:`impactqp.isotonic`).
* ``"kernel"`` – dense impacts with at most ``kernel.MAX_CONTACTS`` contacts: the prepared
  active-set kernel (:mod:`impactqp.kernel`), cached on the problem structure.

Each returns None when it does not apply, so that ``"auto"`` can go on to a QP backend.
"""

from __future__ import annotations

import numpy as np

from .errors import BackendUnsuitableError
from .isotonic import chain_moreau, chain_moreau_batch
from .kernel import MAX_CONTACTS
from .problem import ImpactProblem, ImpactStructure

FAST_PATHS = ("isotonic", "kernel")


def applies(structure: ImpactStructure, backend: str, *, law: str = "moreau") -> str | None:
    """The fast path ``backend`` selects for this structure, or None.

    ``"auto"`` prefers the kernel for small dense impacts (least overhead per call), then
    isotonic regression for chains (O(N) for long ones).

    Raises BackendUnsuitableError when a fast path is named explicitly but cannot be used.
    """
    small = not structure.sparse and 0 < structure.m <= MAX_CONTACTS
    if backend == "kernel" or (backend == "auto" and small):
        if small:
            return "kernel"
        raise BackendUnsuitableError(f"'kernel' takes dense problems with at most "
                                     f"{MAX_CONTACTS} contacts (got m = {structure.m})")
    if backend in ("isotonic", "auto") and law == "moreau" and structure.chain is not None:
        return "isotonic"
    if backend == "isotonic":
        raise BackendUnsuitableError("'isotonic' solves Moreau's law on chains built by "
                                     "iq.chain or iq.newtons_cradle only")
    return None


def moreau_fast(problem: ImpactProblem, eps: float, path: str):
    """(u⁺, Λ, z) by a fast path, or None when the kernel finds no support (q ∉ range G)."""
    st = problem.structure
    if path == "isotonic":
        c = st.chain
        sol = chain_moreau(c.masses, problem.u_minus, eps, left_wall=c.left_wall,
                           right_wall=c.right_wall)
        return sol.u_plus, sol.impulses, sol.z
    lam = st.kernel.solve((1.0 + eps) * problem.gamma_minus)
    if lam is None:
        return None
    u = problem.u_minus + st.impulse_velocity(lam)
    return u, lam, (u + eps * problem.u_minus) / (1.0 + eps)


def lcp_fast(problem: ImpactProblem, q: np.ndarray) -> np.ndarray | None:
    """Λ of the LCP with q by the kernel, or None."""
    return problem.structure.kernel.solve(q)


def moreau_batch_fast(structure: ImpactStructure, U: np.ndarray, eps: float, path: str):
    """(U⁺, Λ, solved mask) for the rows of U by a fast path."""
    if path == "isotonic":
        c = structure.chain
        sol = chain_moreau_batch(c.masses, U, eps, left_wall=c.left_wall,
                                 right_wall=c.right_wall)
        return sol.u_plus, sol.impulses, np.ones(U.shape[0], dtype=bool)
    Gm = structure.Wt_times(U)
    lam, done = structure.kernel.solve_batch((1.0 + eps) * Gm)
    return U + structure.impulse_velocity(lam), lam, done
