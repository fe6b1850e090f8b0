"""The admissible set S = (u⁻ + N) ∩ T_C ∩ B(0, ‖u⁻‖) of post-impact velocities
(docs/theory.md §2).

Membership is decided exactly, without an optimizer: the kinetic condition u ∈ u⁻ + N is a
non-negative least-squares problem for the impulses (correct with redundant contacts, where
Λ is not unique but the residual is), the other two are explicit. The same verdict can be
obtained through the SOCP (distance from u to S), which is how S is handed to optimizers.

S is positively homogeneous in u⁻ and unchanged when M is scaled or a column of W is
scaled by a positive number (docs/theory.md §8): every test here runs on velocities divided
by their largest entry and on a unit-scaled M, so that no square overflows or underflows,
and u⁻ = 0 (S = {0}) is decided exactly.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_vector, check_tol
from ..base.checks import DEFAULT_TOL, UNIT_RANGE, Certificate
from ..errors import InputError
from ..kernels.nnls import solve_nnls
from ..qp.certified import solve_in_forms
from ..qp.cone_solve import solve_cone
from ..qp.cones import Cone, ConeProgram
from ..qp.lcp import solve_psd_lcp
from ..qp.program import QPSolution
from .friction_admissible import friction_coefficients_of, frictional_membership
from .membership import METHODS, OPTIMIZER_TOL, Membership, energy_excess
from .programs import impulse_program, preferred_forms, velocity_program
from .residuals import law_residuals

GRAZING = 1e-12
"""Approach velocities −γᵢ⁻/(sᵢ‖u⁻‖) up to which a contact counts as not approaching in
the SOCP of S (when none approaches, S = {u⁻})."""


def best_impulses(problem: Any, du: np.ndarray) -> tuple[np.ndarray, float]:
    """Λ ≥ 0 minimizing ‖du − M⁻¹WΛ‖ (kinetic norm) and that minimum (docs/theory.md §2,
    kinetic condition). ``du`` is divided by its largest entry first and the answer scaled
    back, so the NNLS sees numbers of order one at any velocity scale.

    Dense: ‖M⁻¹WΛ − du‖_M = ‖BΛ − Lᵀdu‖ with M = LLᵀ, B = L⁻¹W, the compiled exact NNLS.
    Sparse: the NNLS normal equations, an LCP with the Delassus matrix, by a sparse direct
    solve when that already gives Λ ≥ 0 and by a certified QP backend otherwise.
    """
    st = problem.structure
    if st.m == 0:
        return np.zeros(0), problem.norm(du)
    c = float(np.abs(du).max(initial=0.0))
    if c == 0.0:
        return np.zeros(st.m), 0.0
    lam, res = _best_impulses_unit(problem, du / c)
    return lam * c, res * c


def _best_impulses_unit(problem: Any, du: np.ndarray) -> tuple[np.ndarray, float]:
    st = problem.structure
    if not st.sparse:
        lam, res = solve_nnls(st.scaled_W, st.cholesky_factor.T @ du)
        return lam, float(res)
    # sparse: the normal equations of the NNLS are the LCP 0 ≤ Λ ⟂ GΛ − Wᵀdu ≥ 0 (docs/theory.md §3,
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


DRAWING: list = [None]
"""How S is drawn: :func:`impactqp.figures.sections.plot_admissible`, registered there (the
model layer does not import the figures' layer)."""


class AdmissibleSet:
    """The admissible set S of one impact problem (docs/theory.md §2), with friction cones
    for frictional contacts (docs/theory.md §16).

    Obtain it by ``problem.admissible_set()``, or ``problem.admissible_set(mu=...)`` for a
    problem with frictional contacts (``contact_dim`` 2 or 3).

    Parameters
    ----------
    problem : ImpactProblem
    mu : float or (m,) array_like, optional
        Friction coefficients, one or one per contact, each ≥ 0: required for frictional
        contacts, refused for frictionless ones.

    Attributes
    ----------
    mu : (m,) ndarray or None
        The friction coefficients per contact (None for frictionless contacts).

    Raises
    ------
    InputError, ShapeError, NonFiniteError
        ``mu`` missing for frictional contacts or given for frictionless ones, of the wrong
        length, negative, NaN.
    """

    def __init__(self, problem: Any, mu: Any = None) -> None:
        self.problem = problem
        self.radius = problem.norm(problem.u_minus)
        self.mu = friction_coefficients_of(problem, mu)

    def _frictionless(self, what: str) -> None:
        """InputError for what S with friction does not offer (yet): only ``contains``."""
        if self.mu is not None:
            raise InputError(f"{what} is only available for frictionless contacts; for "
                             "frictional ones use contains(), or the frictionless S of "
                             "problem.normal_problem()")

    def moreau_split(self, tol: float = DEFAULT_TOL) -> tuple[np.ndarray, np.ndarray]:
        """(z, z⊥) with z = prox_{T_C}(u⁻) in the metric M, the point of S of least kinetic
        energy, and z⊥ = u⁻ − z (docs/theory.md §1, §3).

        Solved like Moreau's law with ε = 0 (the same programs and exact fast paths), and
        certified by the same residuals.
        """
        p = self.problem.normal_problem()  # T_C is decided by the normal columns
        st = p.structure
        u = p.u_minus
        if st.m == 0 or not np.any(u):
            return u.copy(), np.zeros_like(u)
        scale = float(np.abs(u).max())
        if not UNIT_RANGE[0] <= scale <= UNIT_RANGE[1]:  # z scales with u⁻: order-one units
            z = p.with_u_minus(u / scale).admissible_set().moreau_split()[0] * scale
            return z, u - z
        build = {"velocity": lambda: velocity_program(p),
                 "impulse": lambda: impulse_program(p, p.gamma_minus, 1.0)}

        def finish_for(form: str):
            def finish(sol: QPSolution):
                if form == "velocity":
                    z, lam = sol.x, sol.y
                else:
                    z, lam = u + st.impulse_velocity(sol.x), sol.x
                res = law_residuals(st, u, z, lam, 0.0, eps=0.0)
                return z, Certificate({k: float(v) for k, v in res.items()}, tol)
            return finish

        out = solve_in_forms([(f, build[f], finish_for(f)) for f in preferred_forms(p)],
                             "auto")
        return out.answer, u - out.answer

    def plot(self, path: Any = None, **options: Any) -> Any:
        """Draw a section of S through u⁻ (the plot extra): the same as
        ``iq.plot_admissible(S, path, **options)``, which says what ``options`` take."""
        return DRAWING[0](self, path, **options)

    # --- exact membership -------------------------------------------------------------
    def contains(self, u: Any, method: str = "exact", tol: float | None = None) -> Membership:
        """Decide whether u ∈ S.

        Parameters
        ----------
        u : (n,) array_like
        method : {"exact", "optimizer"}
            ``"exact"``: NNLS for the impulses plus explicit checks. ``"optimizer"``: the
            distance from u to S by the SOCP of :meth:`project`. With friction
            (docs/theory.md §16): ``"exact"`` takes Λ from the momentum equation when W has
            independent columns (Λ unique) and projects it onto the friction cones, and
            falls back to the cone program otherwise; ``"optimizer"`` always solves the cone
            program for the kinetic condition (``distance`` is then None); the membership
            says which was used.
        tol : float, optional
            Tolerance on the dimensionless residuals (default 1e-9 exact, 1e-6 optimizer).
        """
        p = self.problem
        u = as_vector("u", u, p.n_dof)
        if method not in METHODS:
            raise InputError(f"method must be one of {METHODS}, got {method!r}")
        if tol is not None:
            tol = check_tol(tol)
        st = p.structure
        c = float(np.abs(p.u_minus).max(initial=0.0))
        if c == 0.0:  # S = {0}: decided exactly
            zero = not np.any(u)
            bad = 0.0 if zero else float("inf")
            lam = np.zeros(st.m)
            return Membership(zero, bad, bad, bad, lam, method,
                              (DEFAULT_TOL if method == "exact" else OPTIMIZER_TOL)
                              if tol is None else tol, distance=None if method == "exact"
                              else (0.0 if zero else float("inf")))
        if self.mu is not None:
            return frictional_membership(p, self.mu, u, method, tol)
        un, umn = u / c, p.u_minus / c  # the same S, in units of order one
        V = float(st.kinetic_norms(umn))
        lam, res = best_impulses(p, un - umn)
        gamma = st.Wt_times(un)
        s = st.contact_scale
        with np.errstate(over="ignore"):
            kinematic = float(max(0.0, -np.min(gamma / (s * V), initial=0.0)))
        energetic = energy_excess(float(st.kinetic_norms(un) / V))
        kinetic = res / V
        with np.errstate(over="ignore"):  # the verdict is scale-free; impulses beyond the
            lam = lam * c                 # floats are reported as inf
        if method == "exact":
            tol = DEFAULT_TOL if tol is None else tol
            member = bool(max(kinetic, kinematic, energetic) <= tol)
            return Membership(member, kinetic, kinematic, energetic, lam, "exact", tol)
        tol = OPTIMIZER_TOL if tol is None else tol
        dist = float(st.kinetic_norms(un - self._conic(np.zeros(0), point=un)) / V)
        return Membership(bool(dist <= tol), kinetic, kinematic, energetic, lam, "optimizer",
                          tol, distance=dist)

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
        """Solve an SOCP over ξ = (u, Λ, t) ∈ S (a cone program, solved and certified
        through the backend registry by Clarabel, docs/theory.md §9) and return u, all in the
        normalized units of :meth:`contains` (u⁻ divided by its largest entry, M by its
        largest diagonal entry, each column of W by its norm: the same S).

        Objective: min t with ‖F(u − point)‖ ≤ t when ``point`` is given (the distance, linear
        in t, so its accuracy is that of the solver and not its square root), else min cᵀu.
        Rows: M u − WΛ = M u⁻ (zero cone); Λ ≥ 0 and Wᵀu ≥ 0 (non-negative cone);
        (‖u⁻‖, F u) and (t, F(u − point)) in second-order cones, FᵀF = M (the energy ball).
        """
        p = self.problem
        st = p.structure
        n, m = st.n, st.m
        u_minus = p.u_minus / float(np.abs(p.u_minus).max())
        if np.all(st.Wt_times(u_minus) >= -GRAZING * st.contact_scale
                  * float(st.kinetic_norms(u_minus))):
            # no contact approaches: ‖u⁻ + M⁻¹WΛ‖² = ‖u⁻‖² + 2γ⁻ᵀΛ + ΛᵀGΛ > ‖u⁻‖² unless
            # WΛ = 0, so S = {u⁻} (docs/theory.md §2), a set without interior on which
            # no interior-point answer can be certified
            return u_minus
        mu = float(abs(st.M).max())
        M = sp.csc_matrix(st.M) / mu
        W = sp.csc_matrix(st.W) @ sp.diags(1.0 / np.sqrt(np.asarray(
            abs(sp.csc_matrix(st.W)).power(2).sum(axis=0)).ravel()))
        F = sp.csc_matrix(self._mass_root()) / np.sqrt(mu)
        radius = float(np.linalg.norm(F @ u_minus))
        zn1, zm1, znm = sp.csc_matrix((n, 1)), sp.csc_matrix((m, 1)), sp.csc_matrix((n, m))
        row0 = sp.csc_matrix((1, n + m + 1))
        blocks = [[M, -W, zn1],
                  [None, -sp.identity(m), zm1],
                  [-W.T, None, zm1],
                  [row0[:, :n], row0[:, n:n + m], row0[:, -1:]],
                  [-F, znm, zn1]]
        b = [np.asarray(M @ u_minus).ravel(), np.zeros(2 * m), [radius], np.zeros(n)]
        cones = [Cone("zero", n), Cone("nonnegative", 2 * m), Cone("soc", n + 1)]
        if point is not None:
            blocks += [[row0[:, :n], row0[:, n:n + m], sp.csc_matrix([[-1.0]])], [-F, znm, zn1]]
            b += [[0.0], -np.asarray(F @ point).ravel()]
            cones.append(Cone("soc", n + 1))
            q = np.concatenate([np.zeros(n + m), [1.0]])
        else:
            blocks += [[row0[:, :n], row0[:, n:n + m], sp.csc_matrix([[-1.0]])]]
            b += [[0.0]]  # t ≥ 0 keeps the unused variable bounded
            cones.append(Cone("nonnegative", 1))
            q = np.concatenate([c, np.zeros(m), [1.0]])
        program = ConeProgram(None, q, sp.bmat(blocks, format="csc"), np.concatenate(b), cones)
        # certified to the accuracy the answers promise (OPTIMIZER_TOL): a set S without
        # interior makes the multipliers grow without bound and the gap close slowly
        return solve_cone(program, "clarabel", tol=1e-12, accept=OPTIMIZER_TOL).x[:n]

    def project(self, point: Any) -> np.ndarray:
        """Nearest point of S to ``point`` in the kinetic metric (an SOCP, Clarabel):
        minimize ‖u − point‖_M over u ∈ S.

        Parameters
        ----------
        point : (n,) array_like

        Returns
        -------
        (n,) ndarray
            Accurate to about 1e-6 relative (an interior-point solution).
        """
        self._frictionless("project")
        x = as_vector("point", point, self.problem.n_dof)
        c = float(np.abs(self.problem.u_minus).max(initial=0.0))
        if c == 0.0:
            return np.zeros_like(x)
        return self._conic(np.zeros(0), point=x / c) * c

    def support(self, c: Any) -> tuple[float, np.ndarray]:
        """max cᵀu over u ∈ S and a maximiser (an SOCP with a linear objective).

        Parameters
        ----------
        c : (n,) array_like

        Returns
        -------
        value : float
        u : (n,) ndarray
        """
        self._frictionless("support")
        c = as_vector("c", c, self.problem.n_dof)
        scale = float(np.abs(self.problem.u_minus).max(initial=0.0))
        cn = float(np.abs(c).max(initial=0.0))
        if scale == 0.0 or cn == 0.0:
            return 0.0, np.zeros_like(c) if scale == 0.0 else self.problem.u_minus.copy()
        u = self._conic(-c / cn) * scale
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

        self._frictionless("constraints")
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
        mu = "" if self.mu is None else f", mu={np.array2string(self.mu, precision=4)}"
        return f"AdmissibleSet(n_dof={self.problem.n_dof}, radius={self.radius:.6g}{mu})"
