"""Elastic collisions in a chain and the reflection group they generate (docs/theory.md §10).

An elastic collision at contact i alone is the M-orthogonal reflection
``u ← u − 2(γ_i/G_ii) M⁻¹w_i`` across the facet γ_i = 0 of T_C (docs/theory.md §1): it flips γ_i and
applies the impulse ``Λ_i = −2γ_i/G_ii > 0``.  A wall is one more contact (direction e₁ or
−e_N), so chains with one wall are handled too; between two walls T_C = {0} and no elastic
law exists.

When every angle of T_C is π/k_i (:mod:`impactqp.tables.coxeter`) the reflections generate a finite
Coxeter group with T_C as chamber.  Reflecting at a violated contact (γ_i < 0) removes
exactly one reflecting hyperplane of the group from those separating u from T_C, so every
order of collisions stops after the same number of steps at the same velocity: the unique
point u⁺ of the orbit of u⁻ in T_C.  On the chamber g·T_C the law is the M-orthogonal map
g⁻¹, so ``u⁻ ↦ u⁺`` is continuous, piecewise linear, energy conserving and non-expansive,
and u⁺ − u⁻ is a non-negative combination of the M⁻¹w_i: u⁺ ∈ S for every u⁻ (docs/theory.md §2,
§6).
For equal masses (all angles 60°) this is ``sort(u⁻)``, the sector law.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass

import numpy as np

from ..base.arrays import as_dense
from ..errors import InputError, SectorLawError, SolverError
from ..model.builders import require_chain
from ..model.problem import ImpactProblem
from ..model.structure import ChainInfo
from .coxeter import contact_angles, coxeter_labels, coxeter_type, extended_masses, shared_mass

COLLISION_TOL = 1e-12
"""A contact collides when γ_i < −COLLISION_TOL·√G_ii·‖u⁻‖ (rounding is not an approach)."""

MAX_COLLISIONS = 1_000_000
"""Safety cap on the length of a collision sequence."""

MAX_TABLE_ORDER = 5040
"""Largest group whose table is built (A6: 7 equal balls; B5, F4, H3 fit, H4 does not)."""

ORDERS = ("left", "right")


@dataclass(frozen=True)
class ReflectionGroup:
    """The Coxeter group of a chain: labels k_i (angle i = π/k_i), name and order."""

    labels: tuple[int, ...]
    name: str
    order: int
    angles_deg: tuple[float, ...]


# --------------------------------------------------------------------------- collisions
def _chain(problem: ImpactProblem) -> ChainInfo:
    info = require_chain(problem, "reflection law")
    if info.left_wall and info.right_wall:
        raise SectorLawError(
            "a chain between two walls has T_C = {0}: u⁺ = 0 is the only admissible "
            "post-impact velocity, so no energy-conserving (reflection) law exists")
    return info


def elastic_collisions(problem: ImpactProblem, order: str = "left", *,
                       max_collisions: int = MAX_COLLISIONS,
                       ) -> tuple[np.ndarray, np.ndarray, int]:
    """Collide violated contacts (γ_i < 0) one at a time, elastically, until none is left.

    Works for any masses; only for angles π/k is the outcome independent of ``order``.

    Parameters
    ----------
    problem : ImpactProblem
        A chain (``impactqp.chain``), at most one wall.
    order : {"left", "right"}
        Collide the violated contact of smallest (largest) index in W's column order first.
    max_collisions : int
        Raise :class:`SolverError` beyond this many collisions.

    Returns
    -------
    u_plus, impulses, collisions : ndarray, ndarray, int
        ``M(u⁺ − u⁻) = WΛ`` with Λ the sum of the (positive) collision impulses.
    """
    _chain(problem)
    if order not in ORDERS:
        raise InputError(f"order must be one of {ORDERS}, got {order!r}")
    st = problem.structure
    G = st.delassus
    diag, off = list(G.diagonal()), list(G.diagonal(1))
    g = list(st.Wt_times(problem.u_minus))
    m, sign = len(g), 1 if order == "left" else -1
    thresh = [COLLISION_TOL * math.sqrt(d) * problem.velocity_scale for d in diag]
    lam = [0.0] * m
    heap = [sign * i for i in range(m) if g[i] < -thresh[i]]
    heapq.heapify(heap)
    count = 0
    while heap:
        i = sign * heapq.heappop(heap)
        if g[i] >= -thresh[i]:
            continue  # stale entry: already resolved
        count += 1
        if count > max_collisions:
            raise SolverError(f"more than {max_collisions} collisions")
        t = -2.0 * g[i] / diag[i]
        lam[i] += t
        g[i] = -g[i]
        for j, e in ((i - 1, off[i - 1] if i else 0.0), (i + 1, off[i] if i + 1 < m else 0.0)):
            if 0 <= j < m:
                g[j] += t * e
                if g[j] < -thresh[j]:
                    heapq.heappush(heap, sign * j)
    impulses = np.array(lam)
    u_plus = problem.u_minus + st.impulse_velocity(impulses)
    return u_plus, impulses, count


# --------------------------------------------------------------------------- admissibility
def _contact_name(ext: np.ndarray, i: int, left_wall: bool) -> str:
    a, b = (("wall" if math.isinf(ext[j]) else str(j + 1 - left_wall)) for j in (i, i + 1))
    return f"{a}|{b}"


def _vec(u: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.4g}" for x in u) + ")"


def _no_law_message(problem: ImpactProblem, angles: np.ndarray, bad: list[int]) -> str:
    """Why no continuous law exists: the first bad angle, the nearest π/k, the mass that
    would reach it, and two collision orders that disagree."""
    info = require_chain(problem, "reflection law")
    ext = extended_masses(info.masses, info.left_wall, info.right_wall)
    i = bad[0]
    deg = math.degrees(angles[i])
    k = min(range(3, max(4, math.ceil(180.0 / deg)) + 1), key=lambda k: abs(deg - 180.0 / k))
    ball = i + 1 - info.left_wall  # 0-based ball at the corner of contacts i, i+1
    mass = shared_mass(math.pi / k, ext[i], ext[i + 2])
    names = [_contact_name(ext, j, info.left_wall) for j in (i, i + 1)]
    msg = (f"no continuous elastic law: the angle of T_C (kinetic metric) between "
           f"contacts {names[0]} and {names[1]} is {deg:.6g}°, not 180°/k (angles: "
           f"{', '.join(f'{math.degrees(a):.6g}°' for a in angles)}). The nearest attainable "
           f"is 180°/{k} = {180.0 / k:.6g}°, reached with m{ball + 1} = {mass:.6g} (neighbours "
           "kept)")
    msg += "; 90° = 180°/2 would need an infinite mass." if deg > 60.0 else "."
    W = as_dense(problem.structure.W)
    gamma = np.zeros(W.shape[1])
    gamma[[i, i + 1]] = -1.0
    u = np.round(np.linalg.lstsq(W.T, gamma, rcond=None)[0], 12) + 0.0
    q = problem.with_u_minus(u)
    (a, _, na), (b, _, nb) = (elastic_collisions(q, o) for o in ORDERS)
    if np.abs(a - b).max() > 1e-9 * np.abs(u).max():
        msg += (f" Elastic collisions then depend on their order, so the outcome is "
                f"discontinuous: from u⁻ = {_vec(u)}, colliding the leftmost approaching "
                f"contact first gives u⁺ = {_vec(a)} ({na} collisions), the rightmost first "
                f"gives u⁺ = {_vec(b)} ({nb} collisions).")
    return msg


def check_reflection_problem(problem: ImpactProblem) -> ReflectionGroup:
    """The reflection group of a chain problem, or :class:`SectorLawError` saying why no
    continuous elastic law exists (not a chain, two walls, an angle that is not π/k)."""
    _chain(problem)
    if problem.n_contacts == 0:
        return ReflectionGroup((), "trivial", 1, ())
    angles = contact_angles(problem.structure.delassus)
    labels = coxeter_labels(angles)
    degs = tuple(float(math.degrees(a)) for a in angles)
    bad = [i for i, k in enumerate(labels) if k is None]
    if bad:
        raise SectorLawError(_no_law_message(problem, angles, bad))
    kind = coxeter_type(labels)
    if kind is None:  # only within ANGLE_TOL of an affine diagram such as (6, 3)
        raise SectorLawError(f"the angles {degs} are 180°/k for k = {labels}, but that "
                             "Coxeter group is infinite: no finite collision sequence")
    return ReflectionGroup(tuple(int(k) for k in labels), kind[0], kind[1], degs)


