"""Certified solutions of local frictional contact problems (docs/theory.md §15).

Three methods, tried in turn by ``auto``: a projected Gauss–Seidel (NSGS, compiled, on the
compressed rows of W); a semismooth Newton on Alart–Curnier's function with regularized sparse
LU steps and a backtracking line search, from r = 0; a fixed point of second-order cone
programs (Anitescu's relaxation with the De Saxcé term s_c = μ_c‖u_T,c‖ and the skew part of
W lagged from the previous iterate), solved by Clarabel. Each answer is Newton-polished,
projected onto the cones last and certified by
:func:`impactqp.model.friction.certify_friction`; none that fails is returned.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..base.arrays import check_tol
from ..errors import CertificateError, InputError, OutOfRangeError, SolverError
from ..kernels.friction import modified_velocity, nsgs_rows, project_cones
from ..kernels.friction_newton import scales, solve_small
from ..model.friction import (
    ContactUnits,
    FrictionCertificate,
    FrictionContactProblem,
    certify_friction,
)
from ..qp.cone_solve import solve_cone
from ..qp.cones import ConeProgram, friction_cone_rows
from .friction_newton import LSTSQ_MAX, NEWTON_STEPS, FrictionData, lstsq_newton, newton

__all__ = ["FRICTION_BACKENDS", "FrictionResult", "solve_friction"]

FRICTION_BACKENDS = ("auto", "clarabel", "nsgs", "newton")
"""Methods of :func:`solve_friction`: ``newton`` (Alart–Curnier semismooth Newton from
r = 0, then its damped variant), ``clarabel`` (SOCP fixed point, then Newton), ``nsgs``
(projected Gauss–Seidel, then Newton) and ``auto`` (:data:`AUTO`)."""

AUTO = ("nsgs-short", "newton", "clarabel", "newton-damped", "newton-lstsq", "nsgs")
"""The order in which ``auto`` tries the methods: cheapest where each works first (a short
NSGS certifies well-conditioned problems in a few sweeps; Newton from r = 0 most of the
rest; the SOCP route the badly conditioned ones; the least-squares Newton some
rank-deficient ones). The SOCP route, the least-squares Newton and the long NSGS start from
the best answer so far."""

SOCP_ROUNDS = 30
"""Most SOCPs of the fixed point on s = μ‖u_T‖."""
POLISH_STEPS = 20
"""Most Newton steps after NSGS (where they converge they take fewer than 10; where NSGS
failed, Newton from there tends to fail too, and r = 0 is tried next)."""
NEWTON_SHIFT = {"newton": 1.0, "newton-damped": 10.0}
"""The factor κ of the shift κ·min(‖Φ‖/‖Φ(0)‖, 10⁻²)·I added to Newton's Jacobian by each
variant: the damped one converges on some problems where the other stalls, and takes more
steps on the rest."""
NEWTON_FROM = 1e-3
"""Error ‖F‖/‖q‖ below which the SOCP route tries Newton (from farther it tends to stall)."""
NSGS_SWEEPS = 20000
"""Most sweeps of the projected Gauss–Seidel."""
NSGS_SHORT = 100
"""Sweeps of the projected Gauss–Seidel that ``auto`` tries first (cheap where it works)."""
NSGS_MORE = 2000
"""Most sweeps ``nsgs-short`` adds when Newton did not finish in the time the first sweeps'
rate predicts they need (KaplasTower: 1100 sweeps reach 1e-8 in 0.17 s, while Newton from
100 sweeps takes 20 steps, 0.35 s); it adds none when that prediction is above this."""
QUICK_POLISH = 4
"""Newton steps ``nsgs-short`` tries before sweeping on when its sweeps predict they reach
the tolerance within :data:`NSGS_MORE` more (Newton converges in a few steps when it does)."""
NSGS_LOCAL = 3
"""Most projected fixed-point steps on one contact's local problem per sweep (more are
wasted while the other contacts still move: on the FCLib problems 10 took as many sweeps as
3 and cost up to 2.5 times more; 1 took more sweeps on some)."""
SMALL_CONTACTS = 32
"""Most contacts of a problem that ``auto`` first solves in one compiled call, W made dense
(:func:`impactqp.kernels.friction_newton.solve_small`: dense Newton and NSGS, no cone
program); on random well-conditioned problems it beats the general route up to ~50 contacts
(20 contacts: 0.13 ms against 1.3 ms)."""


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
        The method that produced the answer: ``"nsgs-short"``, ``"newton"``,
        ``"clarabel"``, ``"newton-damped"``, ``"newton-lstsq"`` or ``"nsgs"``, with
        ``"+newton"`` when Newton finished it (e.g. ``"clarabel+newton"``), or ``"kernel"``
        (the compiled call of a few contacts)
    """

    r: np.ndarray
    u: np.ndarray
    error: float
    certificate: FrictionCertificate
    iterations: int
    solve_time: float
    backend: str



def solve_friction(problem: FrictionContactProblem, *, backend: str = "auto",
                   tol: float = 1e-8) -> FrictionResult:
    """Solve u = W r + q, r_c ∈ K_μc ⟂ u_c + μ_c‖u_T,c‖e_n ∈ K*_μc with a certificate
    (docs/theory.md §15), in the problem's contacts' units
    (:meth:`~impactqp.FrictionContactProblem.in_contact_units`): r and u are scaled back and
    certified on the problem as given.

    Parameters
    ----------
    problem : FrictionContactProblem
    backend : {"auto", "clarabel", "nsgs", "newton"}
        ``newton``: Alart–Curnier semismooth Newton from r = 0; ``clarabel``: the fixed
        point of SOCPs, then Newton; ``nsgs``: projected Gauss–Seidel, then Newton;
        ``auto``: 100 NSGS sweeps, Newton from r = 0, the SOCP route, the damped Newton, the
        least-squares Newton on the natural map, a long NSGS (docs/theory.md §15); a problem
        of a few contacts first goes whole to one compiled call.
    tol : float
        Tolerance of the certificate: ‖F‖/‖q‖ ≤ tol among others.

    Returns
    -------
    FrictionResult

    Raises
    ------
    CertificateError
        No method reached the tolerance; the message gives the best residuals.
    OutOfRangeError
        The answer is beyond what floats hold in the problem's units.
    """
    if not isinstance(problem, FrictionContactProblem):
        raise InputError(f"problem must be a FrictionContactProblem, got "
                         f"{type(problem).__name__}")
    tol = check_tol(tol)
    if backend not in FRICTION_BACKENDS:
        raise InputError(f"backend must be one of {', '.join(FRICTION_BACKENDS)}, got "
                         f"{backend!r}")
    units = problem.in_contact_units()
    if units.problem is not problem:
        return _rescaled(problem, units, backend, tol)
    start = time.perf_counter()
    if backend == "auto" and problem.n_contacts <= SMALL_CONTACTS:
        small = _solve_small(problem, tol, start)
        if small is not None:
            return small
    data = FrictionData(problem)
    methods = {"auto": AUTO, "newton": ("newton", "newton-damped"), "clarabel": ("clarabel",),
               "nsgs": ("nsgs",)}[backend]
    best: FrictionCertificate | None = None
    r_best = np.zeros_like(data.q)
    failures = []
    for method in methods:
        try:
            polished = False
            if method == "clarabel":
                r, its, polished = _socp_route(data, r_best, tol)
            elif method in NEWTON_SHIFT:
                r, its, _ = newton(data, np.zeros_like(data.q), tol, NEWTON_SHIFT[method])
            elif method == "newton-lstsq":
                if data.n > LSTSQ_MAX:
                    continue
                r, its, _ = lstsq_newton(data, r_best, tol)
            elif method == "nsgs-short":
                r, its, polished = _short_nsgs_route(data, tol)
            else:
                r, its, _ = _nsgs_route(data, r_best, tol, NSGS_SWEEPS)
        except SolverError as exc:
            failures.append(f"{method}: {exc}")
            continue
        if method in ("clarabel", "nsgs") and not polished \
                and data.error(r) > 0.5 * tol:
            steps = NEWTON_STEPS if method == "clarabel" else POLISH_STEPS
            r, its_newton, _ = newton(data, r, tol, max_steps=steps)
            its += its_newton
            polished = True
        name = method + "+newton" if polished else method
        r = project_cones(r, data.mu, data.d)  # r in the cones, exactly, last
        u = problem.velocity(r)
        cert = certify_friction(problem, r, u, tol=tol)
        if cert.ok:
            return FrictionResult(r, u, cert.error, cert, its, time.perf_counter() - start,
                                  name)
        failures.append(f"{method}: {cert.summary()}")
        if best is None or cert.error < best.error:
            best, r_best = cert, r
    raise CertificateError("no method certified the frictional contact problem at tol "
                           f"{tol:.0e}: " + "; ".join(failures))


def _rescaled(problem: FrictionContactProblem, units: ContactUnits, backend: str,
              tol: float) -> FrictionResult:
    """The problem solved in its contacts' units (W̃ = DWD, q̂ = 2⁻ᵏDq: the normal diagonal
    one and max|q̂ᵢ| within :data:`~impactqp.model.friction.QUANTITY_RANGE`), the answer
    scaled back (r = 2ᵏ r̂/s, u = 2ᵏ s∘û) and certified on the problem as given
    (docs/theory.md §15).

    Raises
    ------
    OutOfRangeError
        r or u is beyond the floats, or lands where floats hold it too coarsely for the
        certificate (the answer in contact units was certified).
    """
    start = time.perf_counter()
    found = solve_friction(units.problem, backend=backend, tol=tol)
    r, u = units.reaction(found.r), units.velocity(found.u)
    if not (np.isfinite(r).all() and np.isfinite(u).all()):
        raise OutOfRangeError("the reaction or velocity of this problem is beyond the floats "
                              f"(2^{units.k} times its answer in contact units)")
    cert = certify_friction(problem, r, u, tol=tol)
    if not cert.ok:  # certified in contact units: only the floats' range can lose it here
        raise OutOfRangeError("floats hold the reaction or velocity of this problem too "
                              f"coarsely for its certificate (2^{units.k} times its answer "
                              f"in contact units): {cert.summary()}")
    return FrictionResult(r, u, cert.error, cert, found.iterations,
                          time.perf_counter() - start, found.backend)


def _solve_small(problem: FrictionContactProblem, tol: float,
                 start: float) -> FrictionResult | None:
    """The certified answer of :func:`impactqp.kernels.friction_newton.solve_small`, or None
    to go on to the general route."""
    W = np.ascontiguousarray(problem.dense_W(), dtype=float)
    r = np.empty_like(problem.q)
    its, ok = solve_small(W, problem.q, problem.mu, scales(W.diagonal(), problem.contact_dim),
                          problem.contact_dim, tol, r, NEWTON_STEPS, NSGS_SHORT, NSGS_LOCAL)
    if not ok:
        return None
    u = W @ r + problem.q  # the dense product; the certificate recomputes it from problem.W
    cert = certify_friction(problem, r, u, tol=tol)
    if not cert.ok:
        return None
    return FrictionResult(r, u, cert.error, cert, int(its), time.perf_counter() - start,
                          "kernel")


def _socp(P: sp.csc_matrix, c: np.ndarray, mu: np.ndarray, d: int) -> np.ndarray:
    """min ½ rᵀPr + cᵀr over r ∈ K_μ (one cone per contact): a cone program solved and
    certified through the backend registry (Clarabel; docs/theory.md §9).

    Contacts with μ > 0 are second-order cones (μ r_n, r_T); frictionless ones a
    non-negative r_n and r_T = 0 (a zero cone), listed first."""
    C, cones = friction_cone_rows(mu, d)
    # r is positively homogeneous in c: solved for c of order one (a power of two, exact),
    # where the interior-point tolerances are meant (at max|cᵢ| = 1e50 Clarabel reported
    # the program dual infeasible)
    k = int(np.frexp(np.abs(c).max())[1])
    # an iterate of the fixed point (its end is judged by certify_friction): certified at
    # 1e-6, what Clarabel's answers reach on rank-deficient W (3e-7 measured on PerioBox)
    program = ConeProgram(P, np.ldexp(c, -k), -C, np.zeros(C.shape[0]), cones)
    return np.ldexp(solve_cone(program, "clarabel", tol=1e-10, accept=1e-6).x, k)


def _socp_route(data: FrictionData, r0: np.ndarray, tol: float) -> tuple[np.ndarray, int, bool]:
    """The fixed point of SOCPs on s = μ‖u_T‖e_n and the skew part of W (lagged), halving
    the change of s when the error grows; from an error of :data:`NEWTON_FROM` on, Newton
    is tried each time the error has fallen tenfold, and its answer returned if it passes.
    Returns r, the rounds and Newton steps done, and whether Newton gave r."""
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
            r_pol, steps, ok = newton(data, best_r, tol)
            rounds += steps
            if ok:
                return r_pol, rounds, True
    return best_r, rounds, False


def _lag(data: FrictionData, r: np.ndarray) -> np.ndarray:
    """ũ − u = μ‖u_T‖e_n at u = W r + q: the De Saxcé term the SOCP holds fixed."""
    u = data.velocity(r)
    return modified_velocity(u, data.mu, data.d) - u


def _nsgs_route(data: FrictionData, r0: np.ndarray, tol: float,
                sweeps: int) -> tuple[np.ndarray, int, float]:
    """The compiled projected Gauss–Seidel from r0 to the tolerance (or ``sweeps``), in two
    halves. Returns r, the sweeps done and the sweeps its rate over the second half predicts
    are still needed (0 when done, infinity when the error did not fall)."""
    r = np.array(r0, dtype=float)
    W = data.W
    first = sweeps // 2
    done, err = nsgs_rows(W.indptr, W.indices, W.data, data.q, data.mu, data.d, r, 0.5 * tol,
                          first, NSGS_LOCAL)
    if err <= 0.5 * tol or done == sweeps:
        return r, int(done), 0.0 if err <= 0.5 * tol else math.inf
    more, err_more = nsgs_rows(W.indptr, W.indices, W.data, data.q, data.mu, data.d, r,
                               0.5 * tol, sweeps - first, NSGS_LOCAL)
    if err_more <= 0.5 * tol:
        left = 0.0
    elif 0.0 < err_more < err:
        left = more * math.log(0.5 * tol / err_more) / math.log(err_more / err)
    else:
        left = math.inf
    return r, int(done + more), left


def _short_nsgs_route(data: FrictionData, tol: float) -> tuple[np.ndarray, int, bool]:
    """:data:`NSGS_SHORT` sweeps from r = 0, then Newton from there: :data:`QUICK_POLISH`
    steps when the sweeps' rate predicts they reach the tolerance within :data:`NSGS_MORE`
    more, else up to ``POLISH_STEPS``. When Newton has not succeeded, the sweeps go on from
    their r, in rounds of the predicted number, for as long as
    each round gains a factor ten in ‖F‖ (else their r is returned, to the next method) and
    up to :data:`NSGS_MORE` sweeps, after which Newton is tried again (docs/theory.md §15).
    Returns r, the sweeps and steps done, and whether Newton was run last."""
    r, its, left = _nsgs_route(data, np.zeros_like(data.q), tol, NSGS_SHORT)
    if left == 0.0 and data.error(r) <= 0.5 * tol:
        return r, its, False
    r_pol, steps, ok = newton(data, r, tol,
                              max_steps=QUICK_POLISH if left <= NSGS_MORE else POLISH_STEPS)
    its += steps
    if ok or left > NSGS_MORE or data.error(r_pol) <= 0.5 * tol:
        return r_pol, its, True
    more = 0
    err = data.error(r)
    while more < NSGS_MORE:
        rounds = int(min(max(left, NSGS_SHORT), NSGS_MORE - more))
        r, done, left = _nsgs_route(data, r, tol, rounds)
        more += done
        err_round = data.error(r)
        if err_round <= 0.5 * tol:
            return r, its + more, False
        if not err_round <= 0.1 * err:  # stalling: NSGS will not get there soon
            return r, its + more, False
        err = err_round
    r, steps, _ = newton(data, r, tol, max_steps=POLISH_STEPS)
    return r, its + more + steps, True
