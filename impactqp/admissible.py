"""The admissible set S = (u⁻ + N) ∩ T_C ∩ B(0, ‖u⁻‖) of post-impact velocities (§2).

Membership is decided exactly, without an optimizer: the kinetic condition u ∈ u⁻ + N is a
non-negative least-squares problem for the impulses (correct with redundant contacts, where
Λ is not unique but the residual is), the other two are explicit. The same verdict can be
obtained through the SOCP (distance from u to S), which is how S is handed to optimizers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import clarabel
import numpy as np
import scipy.sparse as sp
from scipy.optimize import nnls

from .backends.clarabel_ import run as run_clarabel
from .certificate import DEFAULT_TOL
from .errors import InputError
from .lcp import solve_psd_lcp
from .problem import ImpactProblem, as_vector

OPTIMIZER_TOL = 1e-6
METHODS = ("exact", "optimizer")


@dataclass(frozen=True)
class Membership:
    """Verdict on u ∈ S with the residual of each condition (dimensionless, §2).

    Attributes
    ----------
    member : bool
        The verdict; the object itself is truthy exactly when it is True.
    kinetic : float
        min over Λ ≥ 0 of ‖u − u⁻ − M⁻¹WΛ‖ / ‖u⁻‖.
    kinematic : float
        Largest penetration velocity −γᵢ / (sᵢ‖u⁻‖), sᵢ = sqrt(Gᵢᵢ), or 0.
    energetic : float
        (‖u‖² − ‖u⁻‖²)₊ / ‖u⁻‖².
    impulses : ndarray
        A Λ ≥ 0 that best explains u − u⁻.
    method : str
        ``"exact"`` or ``"optimizer"``.
    distance : float or None
        With ``method="optimizer"``: ‖u − proj_S(u)‖ / ‖u⁻‖.
    tol : float
    """

    member: bool
    kinetic: float
    kinematic: float
    energetic: float
    impulses: np.ndarray
    method: str
    tol: float
    distance: float | None = None

    def __bool__(self) -> bool:
        return self.member

    @property
    def residuals(self) -> dict[str, float]:
        return {"kinetic": self.kinetic, "kinematic": self.kinematic, "energetic": self.energetic}

    def failed(self) -> list[str]:
        """Names of the conditions that are violated beyond the tolerance."""
        return [k for k, v in self.residuals.items() if v > self.tol]


def best_impulses(problem: ImpactProblem, du: np.ndarray) -> tuple[np.ndarray, float]:
    """Λ ≥ 0 minimizing ‖du − M⁻¹WΛ‖ (kinetic norm) and that minimum (§2, kinetic condition).

    Dense: ‖M⁻¹WΛ − du‖_M = ‖BΛ − Lᵀdu‖ with M = LLᵀ, B = L⁻¹W, scipy's exact NNLS.
    Sparse: the NNLS normal equations, an LCP with the Delassus matrix, by a sparse direct
    solve when that already gives Λ ≥ 0 and by a certified QP backend otherwise.
    """
    st = problem.structure
    if st.m == 0:
        return np.zeros(0), problem.norm(du)
    if not st.sparse:
        lam, res = nnls(st.scaled_W, st.cholesky_factor.T @ du, maxiter=50 * st.m)
        return lam, float(res)
    # sparse: the normal equations of the NNLS are the LCP 0 ≤ Λ ⟂ GΛ − Wᵀdu ≥ 0 (§3,
    # impulse form); with independent contacts its unconstrained solution often already
    # has Λ ≥ 0 (a chain), otherwise a certified QP backend solves it
    g = st.Wt_times(du)
    lu = st.delassus_lu
    lam = None if lu is None else lu.solve(g)
    if lam is None or not np.all(np.isfinite(lam)) or \
            lam.min() < -1e-12 * max(float(np.abs(lam).max(initial=0.0)), 1e-300):
        lam = solve_psd_lcp(st.delassus, -g).z
    lam = np.maximum(lam, 0.0)
    return lam, problem.norm(du - st.impulse_velocity(lam))


class AdmissibleSet:
    """The admissible set S of one impact problem (§2). Obtain it by
    ``problem.admissible_set()``."""

    def __init__(self, problem: ImpactProblem) -> None:
        self.problem = problem
        self.radius = problem.norm(problem.u_minus)

    # --- exact membership -------------------------------------------------------------
    def contains(self, u: Any, method: str = "exact", tol: float | None = None) -> Membership:
        """Decide whether u ∈ S.

        Parameters
        ----------
        u : (n,) array_like
        method : {"exact", "optimizer"}
            ``"exact"``: NNLS for the impulses plus explicit checks. ``"optimizer"``: the
            distance from u to S by the SOCP of :meth:`project`.
        tol : float, optional
            Tolerance on the dimensionless residuals (default 1e-9 exact, 1e-6 optimizer).
        """
        p = self.problem
        u = as_vector("u", u, p.n_dof)
        if method not in METHODS:
            raise InputError(f"method must be one of {METHODS}, got {method!r}")
        V = p.velocity_scale
        lam, res = best_impulses(p, u - p.u_minus)
        st = p.structure
        gamma = st.Wt_times(u)
        s = st.contact_scale
        kinematic = float(max(0.0, -np.min(gamma / (s * V), initial=0.0)))
        energetic = max(0.0, (p.norm(u) ** 2 - self.radius**2) / V**2)
        kinetic = res / V
        if method == "exact":
            tol = DEFAULT_TOL if tol is None else tol
            member = max(kinetic, kinematic, energetic) <= tol
            return Membership(member, kinetic, kinematic, energetic, lam, "exact", tol)
        tol = OPTIMIZER_TOL if tol is None else tol
        dist = p.norm(u - self.project(u)) / V
        return Membership(dist <= tol, kinetic, kinematic, energetic, lam, "optimizer", tol,
                          distance=dist)

    # --- the SOCP -----------------------------------------------------------------------
    def _mass_root(self):
        """F with FᵀF = M (dense Lᵀ or sparse diag(sqrt(m)))."""
        st = self.problem.structure
        if not st.sparse:
            return st.cholesky_factor.T
        if st.diagonal_mass:
            return sp.diags(np.sqrt(st.M.diagonal()), format="csc")
        raise InputError("the SOCP of S needs a factor of M; pass a dense M or a diagonal one")

    def _conic(self, c: np.ndarray, point: np.ndarray | None = None) -> np.ndarray:
        """Solve an SOCP over ξ = (u, Λ, t) ∈ S with Clarabel and return u.

        Objective: min t with ‖F(u − point)‖ ≤ t when ``point`` is given (the distance, linear
        in t, so its accuracy is that of the solver and not its square root), else min cᵀu.
        Rows: M u − WΛ = M u⁻ (zero cone); Λ ≥ 0 and Wᵀu ≥ 0 (non-negative cone);
        (‖u⁻‖, F u) and (t, F(u − point)) in second-order cones, FᵀF = M (the energy ball).
        """
        p = self.problem
        st = p.structure
        n, m = st.n, st.m
        M, W = sp.csc_matrix(st.M), sp.csc_matrix(st.W)
        F = sp.csc_matrix(self._mass_root())
        zn1, zm1, znm = sp.csc_matrix((n, 1)), sp.csc_matrix((m, 1)), sp.csc_matrix((n, m))
        row0 = sp.csc_matrix((1, n + m + 1))
        blocks = [[M, -W, zn1],
                  [None, -sp.identity(m), zm1],
                  [-W.T, None, zm1],
                  [row0[:, :n], row0[:, n:n + m], row0[:, -1:]],
                  [-F, znm, zn1]]
        b = [np.asarray(M @ p.u_minus).ravel(), np.zeros(2 * m), [self.radius], np.zeros(n)]
        cones = [clarabel.ZeroConeT(n), clarabel.NonnegativeConeT(2 * m),
                 clarabel.SecondOrderConeT(n + 1)]
        if point is not None:
            blocks += [[row0[:, :n], row0[:, n:n + m], sp.csc_matrix([[-1.0]])], [-F, znm, zn1]]
            b += [[0.0], -np.asarray(F @ point).ravel()]
            cones.append(clarabel.SecondOrderConeT(n + 1))
            q = np.concatenate([np.zeros(n + m), [1.0]])
        else:
            blocks += [[row0[:, :n], row0[:, n:n + m], sp.csc_matrix([[-1.0]])]]
            b += [[0.0]]  # t ≥ 0 keeps the unused variable bounded
            cones.append(clarabel.NonnegativeConeT(1))
            q = np.concatenate([c, np.zeros(m), [1.0]])
        A = sp.bmat(blocks, format="csc")
        P = sp.csc_matrix((n + m + 1, n + m + 1))
        sol, _ = run_clarabel(P, q, A, np.concatenate(b), cones, 1e-12)
        return np.array(sol.x[:n])

    def project(self, point: Any) -> np.ndarray:
        """Nearest point of S to ``point`` in the kinetic metric (an SOCP, Clarabel):
        minimize ‖u − point‖_M over u ∈ S."""
        x = as_vector("point", point, self.problem.n_dof)
        return self._conic(np.zeros(0), point=x)

    def support(self, c: Any) -> tuple[float, np.ndarray]:
        """max cᵀu over u ∈ S and a maximiser (an SOCP with a linear objective)."""
        c = as_vector("c", c, self.problem.n_dof)
        u = self._conic(-c)
        return float(c @ u), u

    def constraints(self, u_var: Any) -> list:
        """cvxpy constraints that say ``u_var ∈ S`` (the energy ball as a second-order cone).

        Parameters
        ----------
        u_var : cvxpy.Variable or expression of shape (n,)

        Returns
        -------
        list of cvxpy constraints, with an auxiliary impulse variable Λ ≥ 0.
        """
        import cvxpy as cp

        p = self.problem
        if tuple(getattr(u_var, "shape", ())) != (p.n_dof,):
            raise InputError(f"u_var must be a cvxpy expression of shape ({p.n_dof},), got "
                             f"{getattr(u_var, 'shape', None)}")
        st = p.structure
        lam = cp.Variable(st.m, nonneg=True, name="impulses")
        M = st.M
        return [M @ u_var - st.W @ lam == np.asarray(M @ p.u_minus).ravel(),
                st.W.T @ u_var >= 0,
                cp.SOC(cp.Constant(self.radius), self._mass_root() @ u_var)]

    def __repr__(self) -> str:
        return f"AdmissibleSet(n_dof={self.problem.n_dof}, radius={self.radius:.6g})"
