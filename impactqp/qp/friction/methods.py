"""The friction methods of the registry, on :class:`~.newton.FrictionData` (docs/theory.md
§15): a projected Gauss–Seidel (NSGS, compiled, on the compressed rows of W), short or long;
the fixed point of second-order cone programs (Anitescu's relaxation with the De Saxcé term
s_c = μ_c‖u_T,c‖ and the skew part of W lagged from the previous iterate), solved by Clarabel;
and the compiled call that solves a problem of a few contacts whole. The Newton methods are in
:mod:`.newton`. Each returns r and the work done; the certified loop
(:mod:`impactqp.qp.certified`) projects, polishes and certifies.
"""

from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ...errors import SolverError
from ...kernels.friction import modified_velocity, nsgs_contacts, project_cones
from ...kernels.friction_newton import scales, solve_small
from ..cone_solve import solve_cone
from ..cones import ConeProgram, friction_cone_rows
from . import FrictionSolution
from .newton import NEWTON_STEPS, FrictionData, lstsq_newton, newton

SOCP_ROUNDS = 30
"""Most SOCPs of the fixed point on s = μ‖u_T‖."""
POLISH_STEPS = 20
"""Most Newton steps after NSGS (where they converge they take fewer than 10; where NSGS
failed, Newton from there tends to fail too, and r = 0 is tried next: on Capsules-404, whose
sweeps stall at 1.2e-5, 20 steps ended at 3.9e-6, 36 ms, its first two gaining 1.1×)."""
NEWTON_SHIFT = {"newton": 1.0, "newton-damped": 10.0}
"""The factor κ of the shift κ·min(‖Φ‖/‖Φ(0)‖, 10⁻²)·I added to Newton's Jacobian by each
variant: the damped one converges on some problems where the other stalls, and takes more
steps on the rest."""
SOCP_GAIN = 10.0
"""Least factor in ‖F‖ a round of the fixed point gains for the route to go on without trying
Newton (on BoxesStack1 rounds gain 10–40 down to 1e-8, at 15 ms each, while Newton from
2e-6 takes 45 steps, 120 ms)."""
SOCP_STALL = 3
"""Rounds in a row without progress after which the SOCP route hands its best r on (to
Newton's polish): on spheres-in-a-box the fixed point stalls at 1.6e-6 for 26 rounds."""
STALL_NEAR = 1e-4
"""‖F‖/‖q‖ at or below which Newton from r = 0 ends where it stalls (:data:`NEWTON_STALL`) and
the SOCP route does not start from the best answer so far unless that is within
:data:`SOCP_WARM` times the tolerance (docs/theory.md §15). Measured on the 3-D FCLib problems
whose sweeps and Newton fail: Newton stalls near the answer on Capsules-404 (3e-6 from its
10th step to its 42nd) and Capsules-1617 (4e-6, then 1e-7), and the SOCP route from such a
point, or from the sweeps' answer (5e-7 to 4e-6), took 2–6 times longer than from r = 0
(Capsules-404 54 vs 27 ms, Capsules-1617 301–398 vs 71), or ended uncertified (Capsules);
from farther points it did not lose (spheres-in-a-box from Newton's 2e-4: 89 ms, from r = 0
252 ms; BoxesStack1 from 3e-5 or r = 0: 22–33 ms)."""
SOCP_WARM = 10.0
"""Within this many times the tolerance the SOCP route starts from the best answer so far
(Newton's answer that just missed it: Capsules-404 from 2.6e-8 certifies after one round
and four Newton steps)."""
NEWTON_FROM = 1e-3
"""Error ‖F‖/‖q‖ below which the SOCP route tries Newton (from farther it tends to stall)."""
NEWTON_STALL = (8, 1.5, STALL_NEAR)
"""(k, g, e): Newton from r = 0 (``"newton"``, ``"newton-damped"``) stops at the first k steps
in a row that have not divided ‖F‖ by g once ‖F‖/‖q‖ ≤ e (:func:`~.newton.newton`'s
``stall``): stuck there, it crawls through the rest of its 50 steps, and the SOCP route that
follows starts from r = 0 (:data:`STALL_NEAR`). Stopped after 14 steps on Capsules-404 and 23
on Capsules-1617; where Newton converges, on Capsules in 21 steps, its slowest 8 steps in a
row divide ‖F‖ by 2.2."""
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
QUICK_PROBE = 2
"""Of the :data:`QUICK_POLISH` steps, those after which Newton must have divided ‖F‖ by
:data:`QUICK_GAIN` for the rest to be taken (docs/theory.md §22): on KaplasTower and Capsules
its first steps are cut short by the line search and barely lower ‖F‖ (the sweeps finish
there), on PerioBox, FC2D-00727 and FC2D-00237 ‖F‖ halves or better in two steps and Newton
finishes or nearly."""
QUICK_GAIN = 1.25
"""Least factor in ‖F‖ the :data:`QUICK_PROBE` steps gain for the quick polish to go on
(measured after two steps: KaplasTower 1/0.99, Capsules 1/0.96; PerioBox 1/0.52, FC2D-00727
1/0.26, FC2D-00237 1/0.001)."""
RELAX_PLANAR = 1.5
"""Largest over-relaxation factor of the sweeps on planar problems (d = 2;
:func:`impactqp.kernels.friction.nsgs_contacts` takes the factor the plain sweeps' rate
gives, up to this, and sweeps plainly again where it does not pay). Sweeps to 5·10⁻⁹ from
r = 0, plain against over-relaxed: Granular2D-667 40 → 26, FC2D-00071 65 → 39, FC2D-00727
704 → 690, FC2D-00237 359 → 343. 3-D problems sweep plainly: over-relaxed, PerioBox took
958 → 1656 sweeps."""
NSGS_LOCAL = 3
"""Most projected fixed-point steps on one contact's local problem per sweep (more are
wasted while the other contacts still move: on the FCLib problems 10 took as many sweeps as
3 and cost up to 2.5 times more; 1 took more sweeps on some)."""
SMALL_LOCAL = 10
"""Most projected fixed-point steps on one contact's local problem per sweep in the
``"kernel"`` method, whose sweeps run on W's nonzero entries (a contact's row has a few of
them, so its local steps are most of a sweep's work, and solving the local problem further
saves sweeps: FC2D-00031 takes 2 sweeps with 10, 6 with 3; the steps stop once r_c moves by
less than 10⁻⁶‖r_c‖)."""
SMALL_CONTACTS = 32
"""Most contacts of a problem that ``auto`` first solves in one compiled call, W made dense
(:func:`impactqp.kernels.friction_newton.solve_small`: dense Newton and NSGS, no cone
program); on random well-conditioned problems it beats the general route up to ~50 contacts
(20 contacts: 0.13 ms against 1.3 ms)."""


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


def socp_route(data: FrictionData, r0: np.ndarray, tol: float) -> tuple[np.ndarray, int, bool]:
    """The fixed point of SOCPs on s = μ‖u_T‖e_n and the skew part of W (lagged), halving
    the change of s when the error grows. It returns its best r when that is within tol/2,
    and ends after :data:`SOCP_STALL` rounds in a row without progress. From an error of
    :data:`NEWTON_FROM` on, Newton is tried when a round gained less than
    :data:`SOCP_GAIN` (the fixed point slowing; while it gains more, a round costs less than
    Newton's steps) and the error has fallen tenfold since the last try; its answer is
    returned if it passes. Returns r, the rounds and Newton steps done, and whether Newton
    gave r."""
    W, q, mu, d = data.W, data.q, data.mu, data.d
    P = sp.csc_matrix(0.5 * (W + W.T))
    skew = 0.5 * (W - W.T)
    r = r0.copy()
    s = _lag(data, r)
    best_r, best_err = r, data.error(r)
    tried = NEWTON_FROM * 10.0
    rounds = 0
    idle = 0
    for _ in range(SOCP_ROUNDS):
        rounds += 1
        r_new = _socp(P, q + skew @ r + s, mu, d)
        err = data.error(r_new)
        gain = best_err / err if err > 0.0 else math.inf
        if err < best_err:
            best_r, best_err, idle = r_new, err, 0
            r, s = r_new, _lag(data, r_new)
            done = data.finished(best_r, best_err * data.qn, tol)
            if done is not None:
                return done, rounds, False
        else:
            idle += 1
            if idle == SOCP_STALL:
                break
            s = 0.5 * (s + _lag(data, r_new))  # damped
            r = 0.5 * (r + r_new)
        if best_err <= 0.1 * tried and gain < SOCP_GAIN:
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


def nsgs_route(data: FrictionData, r0: np.ndarray, tol: float,
               sweeps: int) -> tuple[np.ndarray, int, float, float]:
    """The compiled projected Gauss–Seidel from r0 to the tolerance (or ``sweeps``), in two
    halves, on W by contacts (kept between solves, :attr:`FrictionData.contacts`),
    over-relaxed on planar problems (:data:`RELAX_PLANAR`). Returns
    r, the sweeps done, the sweeps its rate over the second half predicts are still needed
    (0 when done, infinity when the error did not fall) and ‖F(r)‖/‖q‖."""
    r = np.array(r0, dtype=float)
    rows, steps = data.contacts, data.steps
    relax = RELAX_PLANAR if data.d == 2 else 1.0
    first = sweeps // 2
    done, err = nsgs_contacts(rows, steps, data.q, data.mu, data.d, r, 0.5 * tol, first,
                              NSGS_LOCAL, relax)
    if err <= 0.5 * tol or done == sweeps:
        return r, int(done), 0.0 if err <= 0.5 * tol else math.inf, err
    more, err_more = nsgs_contacts(rows, steps, data.q, data.mu, data.d, r, 0.5 * tol,
                                   sweeps - first, NSGS_LOCAL, relax)
    if err_more <= 0.5 * tol:
        left = 0.0
    elif 0.0 < err_more < err:
        left = more * math.log(0.5 * tol / err_more) / math.log(err_more / err)
    else:
        left = math.inf
    return r, int(done + more), left, err_more


def short_nsgs_route(data: FrictionData, tol: float) -> tuple[np.ndarray, int, bool]:
    """:data:`NSGS_SHORT` sweeps from r = 0, then Newton from there: :data:`QUICK_POLISH`
    steps when the sweeps' rate predicts they reach the tolerance within :data:`NSGS_MORE`
    more, else up to ``POLISH_STEPS`` (either cut short after :data:`QUICK_PROBE` steps that
    have not divided ‖F‖ by :data:`QUICK_GAIN`). When Newton has not succeeded, the sweeps go
    on from their r, in rounds of the predicted number, for as long as each round gains a factor
    ten in ‖F‖ and its rate predicts the tolerance within what is left of
    :data:`NSGS_MORE` sweeps (else their r is returned, to the next method), after which
    Newton is tried again (docs/theory.md §15).
    Returns r, the sweeps and steps done, and whether Newton was run last."""
    r, its, left, err = nsgs_route(data, np.zeros_like(data.q), tol, NSGS_SHORT)
    if left == 0.0:
        return r, its, False
    if left <= NSGS_MORE:  # a quick polish, cut short where Newton is far from converging
        r_pol, steps, ok = newton(data, r, tol, max_steps=QUICK_POLISH,
                                  probe=(QUICK_PROBE, QUICK_GAIN))
    else:  # probed alike: from sweeps that stall, Newton stalled on the FCLib problems
        r_pol, steps, ok = newton(data, r, tol, max_steps=POLISH_STEPS,
                                  probe=(QUICK_PROBE, QUICK_GAIN))
    its += steps
    if ok or left > NSGS_MORE or data.error(r_pol) <= 0.5 * tol:
        return r_pol, its, True
    more = 0
    while more < NSGS_MORE:
        rounds = int(min(max(left, NSGS_SHORT), NSGS_MORE - more))
        r, done, left, err_round = nsgs_route(data, r, tol, rounds)
        more += done
        if err_round <= 0.5 * tol:
            return r, its + more, False
        if not err_round <= 0.1 * err:  # stalling: NSGS will not get there soon
            return r, its + more, False
        if left > NSGS_MORE - more:  # its rate says the rest of the budget falls short
            return r, its + more, False
        err = err_round
    r, steps, _ = newton(data, r, tol, max_steps=POLISH_STEPS)
    return r, its + more + steps, True


def small(data: FrictionData, tol: float) -> FrictionSolution:
    """The ``"kernel"`` method: the problem whole in one compiled call
    (:func:`impactqp.kernels.friction_newton.solve_small`, which leaves r projected onto the
    cones), W made dense.

    Raises
    ------
    SolverError
        The call ended outside half the tolerance (the next method takes over)."""
    W = data.dense
    r = np.empty_like(data.q)
    its, ok = solve_small(W, data.q, data.mu, scales(W.diagonal().copy(), data.d), data.d, tol, r,
                          NEWTON_STEPS, NSGS_SHORT, SMALL_LOCAL)
    if not ok:
        raise SolverError(f"kernel: not within tol/2 after {int(its)} iterations")
    return FrictionSolution(r, int(its), "kernel")


def _from(data: FrictionData, start: np.ndarray | None) -> np.ndarray:
    """Where a method that takes a start begins: ``start``, or r = 0."""
    return np.zeros_like(data.q) if start is None else start


def socp(data: FrictionData, start: np.ndarray | None, tol: float) -> FrictionSolution:
    """The ``"clarabel"`` method: :func:`socp_route` from ``start`` (None: r = 0; r = 0 too
    where its error lies between :data:`SOCP_WARM` times the tolerance and
    :data:`STALL_NEAR`), polished by Newton when it ends short of the tolerance."""
    if start is not None and SOCP_WARM * tol < data.error(start) <= STALL_NEAR:
        start = None
    r, its, finished = socp_route(data, _from(data, start), tol)
    return FrictionSolution(project_cones(r, data.mu, data.d), its, "clarabel",
                            0 if finished else NEWTON_STEPS)


def gauss_seidel(data: FrictionData, start: np.ndarray | None, tol: float,
                 method: str) -> FrictionSolution:
    """The ``"nsgs-short"`` method (:func:`short_nsgs_route` from r = 0) and the ``"nsgs"``
    one (:data:`NSGS_SWEEPS` sweeps from ``start``, then up to :data:`POLISH_STEPS` Newton
    steps when short of the tolerance)."""
    if method == "nsgs-short":
        r, its, _ = short_nsgs_route(data, tol)
        return FrictionSolution(project_cones(r, data.mu, data.d), its, method)
    r, its, _, _ = nsgs_route(data, _from(data, start), tol, NSGS_SWEEPS)
    return FrictionSolution(project_cones(r, data.mu, data.d), its, method, POLISH_STEPS)


def newton_method(data: FrictionData, start: np.ndarray | None, tol: float,
                  method: str) -> FrictionSolution:
    """The ``"newton"`` and ``"newton-damped"`` methods (Alart–Curnier's Newton from r = 0
    with the shift factor of :data:`NEWTON_SHIFT`, ended where it stalls,
    :data:`NEWTON_STALL`) and ``"newton-lstsq"`` (the least-squares
    Newton on the natural map from ``start``); both end with r projected onto the cones."""
    if method == "newton-lstsq":
        r, its, _ = lstsq_newton(data, _from(data, start), tol)
    else:
        r, its, _ = newton(data, np.zeros_like(data.q), tol, NEWTON_SHIFT[method],
                           stall=NEWTON_STALL)
    return FrictionSolution(r, its, method)
