"""Certified solutions of local frictional contact problems (docs/theory.md §15).

The default route: a fixed point of second-order cone programs (Anitescu's relaxation with
the De Saxcé term s_c = μ_c‖u_T,c‖ and the skew part of W lagged from the previous
iterate), solved by Clarabel, brings r close; a semismooth Newton on the natural map with
minimum-norm least-squares steps and a backtracking line search finishes. A projected
Gauss–Seidel (NSGS, compiled) is the fallback and an alternative backend. Every answer is
projected onto the cones last and certified by :func:`impactqp.model.friction.certify_friction`;
none that fails is returned.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from ..base.arrays import check_tol
from ..errors import CertificateError, InputError, SolverError
from ..kernels.friction import (
    modified_velocity,
    modified_velocity_jacobian,
    natural_map,
    nsgs,
    project_cones,
    projection_jacobian,
)
from ..model.friction import FrictionCertificate, FrictionContactProblem, certify_friction
from ..qp.cone_solve import solve_cone
from ..qp.cones import ConeProgram, friction_cone_rows

__all__ = ["FRICTION_BACKENDS", "FrictionResult", "solve_friction"]

FRICTION_BACKENDS = ("auto", "clarabel", "nsgs")
"""Methods of :func:`solve_friction`: ``clarabel`` (SOCP fixed point, then Newton), ``nsgs``
(projected Gauss–Seidel, then Newton) and ``auto`` (a short NSGS, then the SOCP route, then
a long NSGS, each warm-started from the best answer so far and Newton-polished)."""

SOCP_ROUNDS = 30
"""Most SOCPs of the fixed point on s = μ‖u_T‖."""
NEWTON_STEPS = 60
"""Most Newton steps of the polish."""
NEWTON_FROM = 1e-3
"""Error ‖F‖/‖q‖ below which the SOCP route tries Newton (from farther it tends to stall)."""
NSGS_SWEEPS = 20000
"""Most sweeps of the projected Gauss–Seidel."""
NSGS_SHORT = 100
"""Sweeps of the projected Gauss–Seidel that ``auto`` tries first (cheap where it works)."""


@dataclass(frozen=True)
class FrictionResult:
    """A certified answer of :func:`solve_friction`.

    Attributes
    ----------
    r, u : ndarray
        The reaction and the velocity u = W r + q.
    error : float
        ‖F‖/‖q‖, the natural-map error of the certificate (ABH).
    certificate : FrictionCertificate
        The recomputed checks; ``certificate.ok`` is always True here.
    iterations : int
        SOCPs (or sweeps) plus Newton steps done.
    solve_time : float
        Wall-clock seconds.
    backend : str
        The method that produced the answer, e.g. ``"clarabel-socp+newton"``.
    """

    r: np.ndarray
    u: np.ndarray
    error: float
    certificate: FrictionCertificate
    iterations: int
    solve_time: float
    backend: str


class _Data:
    """The problem's arrays as the solvers use them (W dense, its symmetric part)."""

    def __init__(self, problem: FrictionContactProblem) -> None:
        self.W = np.ascontiguousarray(problem.dense_W())
        self.q = problem.q
        self.mu = problem.mu
        self.d = problem.contact_dim
        self.qn = float(np.linalg.norm(self.q)) or 1.0

    def error(self, r: np.ndarray) -> float:
        """‖F(r)‖/‖q‖."""
        return float(np.linalg.norm(natural_map(r, self.W @ r + self.q, self.mu, self.d))) / self.qn


def solve_friction(problem: FrictionContactProblem, *, backend: str = "auto",
                   tol: float = 1e-8) -> FrictionResult:
    """Solve u = W r + q, r_c ∈ K_μc ⟂ u_c + μ_c‖u_T,c‖e_n ∈ K*_μc with a certificate
    (docs/theory.md §15).

    Parameters
    ----------
    problem : FrictionContactProblem
    backend : {"auto", "clarabel", "nsgs"}
        ``clarabel``: the fixed point of SOCPs, then Newton; ``nsgs``: projected
        Gauss–Seidel, then Newton; ``auto``: 100 NSGS sweeps, then the SOCP route, then a
        long NSGS, each warm-started from the best answer so far.
    tol : float
        Tolerance of the certificate: ‖F‖/‖q‖ ≤ tol among others.

    Returns
    -------
    FrictionResult

    Raises
    ------
    CertificateError
        No method reached the tolerance; the message gives the best residuals.
    """
    if not isinstance(problem, FrictionContactProblem):
        raise InputError(f"problem must be a FrictionContactProblem, got "
                         f"{type(problem).__name__}")
    tol = check_tol(tol)
    if backend not in FRICTION_BACKENDS:
        raise InputError(f"backend must be one of {', '.join(FRICTION_BACKENDS)}, got "
                         f"{backend!r}")
    start = time.perf_counter()
    data = _Data(problem)
    methods = {"auto": ("nsgs-short", "clarabel", "nsgs"), "clarabel": ("clarabel",),
               "nsgs": ("nsgs",)}[backend]
    best: FrictionCertificate | None = None
    r_best = np.zeros_like(data.q)
    failures = []
    for method in methods:
        try:
            if method == "clarabel":
                r, its = _socp_route(data, r_best, tol)
            else:
                sweeps = NSGS_SHORT if method == "nsgs-short" else NSGS_SWEEPS
                r, its = _nsgs_route(data, r_best, tol, sweeps)
        except SolverError as exc:
            failures.append(f"{method}: {exc}")
            continue
        r, its_newton, _ = _newton(data, r, tol)  # r in the cones, exactly, last
        u = problem.velocity(r)
        cert = certify_friction(problem, r, u, tol=tol)
        if cert.ok:
            return FrictionResult(r, u, cert.error, cert, its + its_newton,
                                  time.perf_counter() - start, f"{method}+newton")
        failures.append(f"{method}: {cert.summary()}")
        if best is None or cert.error < best.error:
            best, r_best = cert, r
    raise CertificateError("no method certified the frictional contact problem at tol "
                           f"{tol:.0e}: " + "; ".join(failures))


def _socp(P: sp.csc_matrix, c: np.ndarray, mu: np.ndarray, d: int) -> np.ndarray:
    """min ½ rᵀPr + cᵀr over r ∈ K_μ (one cone per contact): a cone program solved and
    certified through the backend registry (Clarabel; docs/theory.md §9).

    Contacts with μ > 0 are second-order cones (μ r_n, r_T); frictionless ones a
    non-negative r_n and r_T = 0 (a zero cone), listed first."""
    C, cones = friction_cone_rows(mu, d)
    # an iterate of the fixed point (its end is judged by certify_friction): certified at
    # 1e-6, what Clarabel's answers reach on rank-deficient W (3e-7 measured on PerioBox)
    program = ConeProgram(P, c, -C, np.zeros(C.shape[0]), cones)
    return solve_cone(program, "clarabel", tol=1e-10, accept=1e-6).x


def _socp_route(data: _Data, r0: np.ndarray, tol: float) -> tuple[np.ndarray, int]:
    """The fixed point of SOCPs on s = μ‖u_T‖e_n and the skew part of W (lagged), halving
    the change of s when the error grows; from an error of :data:`NEWTON_FROM` on, Newton
    is tried each time the error has fallen tenfold, and its answer returned if it passes."""
    W, q, mu, d = data.W, data.q, data.mu, data.d
    P = sp.csc_matrix(0.5 * (W + W.T))
    skew = 0.5 * (W - W.T)
    r = r0.copy()
    s = _lag(data, r)
    best_r, best_err = r, data.error(r)
    tried = NEWTON_FROM * 10.0
    rounds = 0
    for _ in range(SOCP_ROUNDS):
        rounds += 1
        r_new = _socp(P, q + skew @ r + s, mu, d)
        err = data.error(r_new)
        if err < best_err:
            best_r, best_err = r_new, err
            r, s = r_new, _lag(data, r_new)
        else:
            s = 0.5 * (s + _lag(data, r_new))  # damped
            r = 0.5 * (r + r_new)
        if best_err <= 0.1 * tried:
            tried = best_err
            r_pol, steps, ok = _newton(data, best_r, tol)
            rounds += steps
            if ok:
                return r_pol, rounds
    return best_r, rounds


def _lag(data: _Data, r: np.ndarray) -> np.ndarray:
    """ũ − u = μ‖u_T‖e_n at u = W r + q: the De Saxcé term the SOCP holds fixed."""
    u = data.W @ r + data.q
    return modified_velocity(u, data.mu, data.d) - u


def _nsgs_route(data: _Data, r0: np.ndarray, tol: float,
                sweeps: int) -> tuple[np.ndarray, int]:
    """The compiled projected Gauss–Seidel from r0 to the tolerance (or ``sweeps``)."""
    r = np.array(r0, dtype=float)
    sweeps, _ = nsgs(data.W, data.q, data.mu, data.d, r, 0.5 * tol, sweeps, 100)
    return r, int(sweeps)


def _newton(data: _Data, r: np.ndarray, tol: float) -> tuple[np.ndarray, int, bool]:
    """Semismooth Newton on F(r) = r − P_K(r − ũ(Wr + q)): minimum-norm least-squares steps
    J Δ = −F (J singular where W is rank-deficient) and backtracking on ‖F‖.

    Returns P_K(r) (r projected onto the cones), the steps done, and whether that projected
    r is within tol/2: Newton goes on past ‖F‖ ≤ tol/2 until it is (projecting moves r by up
    to ‖F‖, hence u by up to ‖W‖‖F‖)."""
    W, q, mu, d = data.W, data.q, data.mu, data.d
    n = r.size
    m = mu.size
    u = W @ r + q
    F = natural_map(r, u, mu, d)
    f = float(np.linalg.norm(F))
    steps = 0
    while True:
        if f <= 0.5 * tol * data.qn:
            rp = project_cones(r, mu, d)
            if data.error(rp) <= 0.5 * tol:
                return rp, steps, True
        if steps == NEWTON_STEPS:
            break
        steps += 1
        x = r - modified_velocity(u, mu, d)
        DP = projection_jacobian(x, mu, d)
        DU = modified_velocity_jacobian(u, mu, d)
        DUW = np.einsum("cij,cjk->cik", DU, W.reshape(m, d, n))
        J = np.einsum("cij,cjk->cik", DP, DUW).reshape(n, n) + np.eye(n)
        J -= sla.block_diag(*DP)
        step = sla.lstsq(J, -F, lapack_driver="gelsy", check_finite=False)[0]
        t = 1.0
        while t > 1e-8:
            r_try = r + t * step
            u_try = W @ r_try + q
            F_try = natural_map(r_try, u_try, mu, d)
            f_try = float(np.linalg.norm(F_try))
            if f_try <= (1.0 - 1e-4 * t) * f:
                break
            t *= 0.5
        else:
            break  # no descent: stalled
        r, u, F, f = r_try, u_try, F_try, f_try
    return project_cones(r, mu, d), steps, False
