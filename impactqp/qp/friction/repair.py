"""Newton with local repairs (docs/theory.md §22): where the semismooth Newton on
Alart–Curnier's function stalls at a stationary point of its merit that is not a solution,
and the natural map's residual sits on a few contacts, the problem restricted to those
contacts and their neighbours (the other reactions held) is solved by the fixed point of cone
programs, and Newton restarts from the repaired reaction.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ...errors import CertificateError, SolverError
from ...kernels.friction import natural_map, project_cones
from . import FrictionSolution
from .methods import POLISH_STEPS, socp_route
from .newton import FrictionData, newton

REPAIR_ROUNDS = 6
"""Most rounds of repair then Newton (on Granular2D-2020 the third certifies; where the
residual is spread over the whole problem, as on RockPile, the clusters are too large or the
rounds stop gaining, and the route ends)."""
REPAIR_IDLE = 3
"""Rounds in a row that do not lower the best ‖F‖ after which the route gives up."""
REPAIR_SHARE = 0.99
"""Share of ‖F‖² the seed contacts of a repair carry."""
REPAIR_SEEDS = 16
"""Most seed contacts of a repair (the contacts with the largest ‖F_c‖)."""
REPAIR_MAX = 96
"""Most contacts of a repaired sub-problem (the seeds and their neighbours in W): beyond it
the residual is not local and a repair would be a whole solve."""


class SubProblem(NamedTuple):
    """The problem restricted to some contacts, the other reactions held: u_S = W_SS r_S +
    (q_S + W_SS̄ r_S̄) (a :class:`~impactqp.qp.friction.FrictionProgram`)."""

    W: sp.csr_matrix
    q: np.ndarray
    mu: np.ndarray
    contact_dim: int
    n_contacts: int


def residual_cluster(data: FrictionData, r: np.ndarray) -> np.ndarray:
    """The rows of the contacts a repair solves at r: the fewest contacts carrying
    :data:`REPAIR_SHARE` of ‖F(r)‖² (at most :data:`REPAIR_SEEDS`) and every contact W couples
    them to; empty when they are more than :data:`REPAIR_MAX`."""
    d, m = data.d, data.mu.size
    F = natural_map(r, data.velocity(r), data.mu, d)
    per = (F.reshape(m, d) ** 2).sum(axis=1)
    order = np.argsort(-per)
    share = np.cumsum(per[order]) / max(per.sum(), np.finfo(float).tiny)
    seeds = order[:min(int(np.searchsorted(share, REPAIR_SHARE)) + 1, REPAIR_SEEDS)]
    seed_rows = (seeds[:, None] * d + np.arange(d)).ravel()
    contacts = np.union1d(seeds, np.unique(data.W[seed_rows].indices // d))
    if contacts.size > REPAIR_MAX:
        return np.empty(0, dtype=np.int64)
    return (contacts[:, None] * d + np.arange(d)).ravel()


def sub_problem(data: FrictionData, r: np.ndarray, rows: np.ndarray) -> FrictionData:
    """The problem on ``rows`` with the other reactions held at r (:class:`SubProblem`)."""
    W = data.W
    held = r.copy()
    held[rows] = 0.0
    block = W[rows]
    q = data.q[rows] + block @ held
    contacts = rows[::data.d] // data.d
    return FrictionData(SubProblem(sp.csr_matrix(block[:, rows]), q, data.mu[contacts],
                                   data.d, contacts.size))


def repair(data: FrictionData, r: np.ndarray, tol: float) -> tuple[np.ndarray, int]:
    """r with its residual's cluster (:func:`residual_cluster`) replaced by the sub-problem's
    answer from the fixed point of cone programs (:func:`~.methods.socp_route`) from the
    current r_S, finished by Newton (Newton alone where Clarabel does not certify one of its
    programs), when that answer lowers ‖F‖ on the sub-problem; also the cone programs and
    Newton steps done (0: no repair)."""
    rows = residual_cluster(data, r)
    if rows.size == 0:
        return r, 0
    sub = sub_problem(data, r, rows)
    before = sub.error(r[rows])
    try:
        r_sub, rounds, by_newton = socp_route(sub, r[rows], tol)
    except (CertificateError, SolverError):  # a cone program Clarabel did not certify
        r_sub, rounds, by_newton = r[rows], 0, False
    if not by_newton:
        r_sub, steps, _ = newton(sub, r_sub, tol)
        rounds += steps
    r_sub = project_cones(r_sub, sub.mu, sub.d)
    if not sub.error(r_sub) < before:
        return r, rounds
    repaired = r.copy()
    repaired[rows] = r_sub
    return repaired, rounds


def repair_route(data: FrictionData, start: np.ndarray | None,
                 tol: float) -> tuple[np.ndarray, int, bool]:
    """Rounds of :func:`repair` then Newton (at most :data:`~.methods.POLISH_STEPS` steps)
    from ``start`` (None: Newton from r = 0 first), at most :data:`REPAIR_ROUNDS`, until
    Newton reaches tol/2, a repair of Newton's last r finds nothing local to solve, or
    :data:`REPAIR_IDLE` rounds in a row do not lower the best ‖F‖. Returns the best r
    (projected onto the cones), the cone programs and Newton steps done, and whether r is
    within tol/2."""
    its = 0
    if start is None:
        r, its, ok = newton(data, np.zeros_like(data.q), tol, max_steps=POLISH_STEPS)
        if ok:
            return r, its, True
    else:
        r = project_cones(start, data.mu, data.d)
    best, best_err = r, data.error(r)
    idle = 0
    for _ in range(REPAIR_ROUNDS):
        repaired, rounds = repair(data, r, tol)
        its += rounds
        if repaired is r:
            break
        r, steps, ok = newton(data, repaired, tol, max_steps=POLISH_STEPS)
        its += steps
        if ok:
            return r, its, True
        err = data.error(r)
        if err < best_err:
            best, best_err, idle = r, err, 0
        else:
            idle += 1
            if idle == REPAIR_IDLE:
                break
    return best, its, False


def repaired_newton(data: FrictionData, start: np.ndarray | None,
                    tol: float) -> FrictionSolution:
    """The ``"newton-repair"`` method: :func:`repair_route` from ``start``."""
    r, its, _ = repair_route(data, start, tol)
    return FrictionSolution(r, its, "newton-repair")
