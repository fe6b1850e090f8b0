"""The admissible set S with friction (docs/theory.md §16): post-impact velocities reached by
impulses in the friction cones.

For frictional contacts (d = 2 or 3 columns of W per contact, the normal first) u belongs to
S when three conditions hold:

- kinetic: u − u⁻ = M⁻¹WΛ for some Λ with every Λ_c in the cone K_μc = {‖Λ_T‖ ≤ μ_c Λ_n};
- kinematic: the normal contact velocities W_nᵀu are ≥ 0 (the tangents are free);
- energetic: ‖u‖ ≤ ‖u⁻‖ in the kinetic metric.

The kinetic condition is decided exactly where Λ is unique (W of full column rank): Λ is the
least-squares solution of the momentum equation, projected onto the cones, and the
residual of that projected Λ is the verdict. Otherwise (and with ``method="optimizer"``)
it is the distance min over Λ in the cones of ‖u − u⁻ − M⁻¹WΛ‖, a second-order cone
program (:func:`cone_least_squares`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_dense
from ..base.checks import DEFAULT_TOL
from ..base.cholesky import cholesky_solve
from ..errors import InputError
from ..kernels.friction import project_cones
from ..kernels.units import contact_units
from ..qp.cone_solve import solve_cone
from ..qp.cones import Cone, ConeProgram, friction_cone_rows
from .friction import friction_coefficients
from .membership import OPTIMIZER_TOL, Membership, energy_excess

__all__ = ["cone_least_squares", "friction_coefficients", "friction_coefficients_of",
           "frictional_membership"]

SOCP_TOL = 1e-12
"""Clarabel's tolerance for the distance program (its objective is the distance itself)."""


def _finite_or_inf(x: float) -> float:
    """x, or +inf where it is NaN (a residual that cannot be evaluated fails)."""
    return x if x == x else float("inf")


def friction_coefficients_of(problem: Any, mu: Any) -> np.ndarray | None:
    """The μ of S for ``problem``: one per contact for frictional contacts (required), None
    for frictionless ones (where giving μ is an InputError)."""
    frictional = problem.contact_dim > 1
    if frictional and mu is None:
        raise InputError("the admissible set of frictional contacts depends on the friction "
                         "coefficients: pass problem.admissible_set(mu=...)")
    if not frictional and mu is not None:
        raise InputError("mu applies to frictional contacts (contact_dim 2 or 3); this "
                         "problem's contacts are frictionless: call admissible_set()")
    return friction_coefficients(mu, problem.n_contacts) if frictional else None


def _metric_factor(structure: Any) -> tuple[np.ndarray, np.ndarray]:
    """(B, Lᵀ) with M = LLᵀ and B = L⁻¹W: ‖du − M⁻¹WΛ‖_M = ‖BΛ − Lᵀdu‖."""
    if not structure.sparse:
        return structure.scaled_W, structure.cholesky_factor.T
    L = np.linalg.cholesky(as_dense(structure.M))
    return cholesky_solve(L, np.asarray(as_dense(structure.W), dtype=float)), L.T


def cone_least_squares(B: np.ndarray, b: np.ndarray, mu: np.ndarray, d: int) -> np.ndarray:
    """Λ minimizing ‖BΛ − b‖ over Λ_c ∈ K_μc (one friction cone per contact, d components,
    the normal first): the second-order cone program, solved and certified through the
    solver layer (Clarabel; docs/theory.md §9),

        min t  s.t.  (t, b − BΛ) ∈ SOC,  (μ_c Λ_n,c, Λ_T,c) ∈ SOC for μ_c > 0,
                     Λ_n,c ≥ 0 and Λ_T,c = 0 for μ_c = 0.

    Returns Λ projected onto the cones (the interior-point answer may sit just outside).
    """
    k, n = B.shape[1], B.shape[0]
    C, cones = friction_cone_rows(mu, d)
    t_row = sp.csc_matrix(([-1.0], ([0], [k])), shape=(1, k + 1))  # s₀ = t
    A = sp.vstack([t_row, sp.hstack([sp.csc_matrix(B), sp.csc_matrix((n, 1))]),  # b − BΛ
                   sp.hstack([-C, sp.csc_matrix((C.shape[0], 1))])], format="csc")
    rhs = np.concatenate([[0.0], b, np.zeros(C.shape[0])])
    cost = np.zeros(k + 1)
    cost[-1] = 1.0
    program = ConeProgram(None, cost, A, rhs, [Cone("soc", n + 1), *cones])
    sol = solve_cone(program, "clarabel", tol=SOCP_TOL, accept=1e-6)
    return project_cones(np.array(sol.x[:k]), mu, d)


def frictional_membership(problem: Any, mu: np.ndarray, u: np.ndarray, method: str,
                          tol: float | None) -> Membership:
    """The verdict on u ∈ S with friction (docs/theory.md §16), in the order-one units of
    :meth:`~impactqp.AdmissibleSet.contains` (u⁻ ≠ 0): the kinetic condition exactly
    (``method="exact"`` and W of full column rank) or by :func:`cone_least_squares`
    (``"optimizer"``, or Λ not unique), which ``Membership.method`` reports; ``tol``
    None is the default of the method used.
    """
    st = problem.structure
    d = st.contact_dim
    c = float(np.abs(problem.u_minus).max())
    un, umn = u / c, problem.u_minus / c  # the same S, in units of order one
    V = float(st.kinetic_norms(umn))
    B, Lt = _metric_factor(st)
    b = Lt @ (un - umn)
    exact = method == "exact" and st.full_column_rank
    units = contact_units(np.ascontiguousarray(st.delassus_diagonal, dtype=float), d)
    if exact:
        lam = project_cones(np.linalg.lstsq(B, b, rcond=None)[0], mu, d)
    else:  # in contact units (Λ̃_c = s_cΛ_c/V, one factor a contact: the cones stay, s_c
        # of kernels.units), so the interior-point solver sees an order-one program
        # whatever the unit of mass
        lam = cone_least_squares(B / units, b / V, mu, d) * (V / units)
    with np.errstate(over="ignore", invalid="ignore"):  # far outside S: inf, not an error
        kinetic = _finite_or_inf(float(np.linalg.norm(B @ lam - b)) / V)
        gamma_n = st.Wt_times(un)[::d]
        kinematic = _finite_or_inf(float(max(0.0, -np.min(gamma_n / (units[::d] * V),
                                                          initial=0.0))))
    energetic = energy_excess(float(st.kinetic_norms(un) / V))
    with np.errstate(over="ignore"):  # impulses beyond the floats are reported as inf
        lam = lam * c
    if tol is None:
        tol = DEFAULT_TOL if exact else OPTIMIZER_TOL
    return Membership(bool(max(kinetic, kinematic, energetic) <= tol), kinetic, kinematic,
                      energetic, lam, "exact" if exact else "optimizer", tol)
