"""Exact certificate of a piecewise-linear impact law on simplicial cones (docs/theory.md §7).

Works on any object shaped like :class:`impactqp.tables.sector_table.SectorTable` (``cones`` with
``rays``/``Q``/``label``, ``G``, ``W``, ``mass``), or with a mass matrix ``M`` instead of
``mass`` (unequal masses, :mod:`impactqp.tables.reflection_table`).  Every check is vectorised over
the cones, so the 40 320 cones of eight balls are certified in seconds.

Checks (docs/theory.md §7, §6):

* kinematic   ``Q r_k ≥ 0`` for every extreme ray;
* kinetic     ``G⁻¹(Q − I) r_k ≥ 0`` (the impulse Λ is compressive);
* energetic   ``γᵀ(G⁻¹ − QᵀG⁻¹Q)γ ≥ 0`` on the cone, i.e. ``C = Rᵀ(G⁻¹ − QᵀG⁻¹Q)R``
  copositive (``γ = Rc``, ``c ≥ 0``);
* continuity  neighbouring cones (sharing n−2 rays) agree on their shared rays;
* non-expansive  ``λ_max(G QᵀG⁻¹Q) ≤ 1`` per piece, and ``‖A‖_M ≤ 1`` for the induced
  velocity map ``A = I + M⁻¹WG⁻¹(Q − I)Wᵀ``.

A continuous piecewise-linear map whose pieces are non-expansive is non-expansive,
which for impact laws is maximal monotonicity (docs/theory.md §6).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..base.checks import Certificate

FloatArray = NDArray[np.float64]

TOL = 1e-12
"""Absolute tolerance of every check, scaled by the size of the matrices involved."""


@dataclass(frozen=True)
class ConeCheck:
    """docs/theory.md §7 results for one cone; margins are minima (≥ 0 passes) or maxima (≤ 1
    passes)."""

    label: str
    kinematic_margin: float  # min_k min_i (Q r_k)_i
    kinetic_margin: float  # min_k min_i (G⁻¹(Q − I) r_k)_i
    energetic_margin: float  # min of cᵀCc over c ≥ 0, ‖c‖ = 1
    expansion: float  # λ_max(G QᵀG⁻¹Q)
    velocity_norm: float  # ‖A‖_M of the induced velocity map
    kinematic: bool
    kinetic: bool
    energetic: bool
    non_expansive: bool
    velocity_non_expansive: bool


@dataclass(frozen=True)
class CheckResult:
    """One global check: ``passed``, its numeric ``margin`` and where it is worst."""

    name: str
    passed: bool
    margin: float
    worst: str
    meaning: str

    def line(self) -> str:
        """One summary line: name, PASS/FAIL, margin and worst cone."""
        flag = "PASS" if self.passed else "FAIL"
        return (f"  {self.name:<23} {flag}  {self.meaning} = {self.margin:.3g}"
                f"  (worst: {self.worst})")


TABLE_CHECKS = {"kinematic": "kinematic_cones", "kinetic": "kinetic_cones",
                "energetic": "energetic_cones", "continuity": "discontinuous_pairs",
                "non_expansive": "expanding_cones",
                "velocity_non_expansive": "velocity_expanding_cones"}
"""Each global check of a table (its extra, a :class:`CheckResult`) and the residual that
counts where it fails: cones (or, for continuity, neighbour pairs) that fail it."""

TableCertificate = Certificate
"""The exact certificate of a table is a :class:`~impactqp.results.Certificate` (made by
:func:`certify_sector_table`); the name is kept for code written before there was one
type."""


def table_report(cert: Certificate) -> str:
    """Plain-text report of a table's certificate, one line per check and the verdict on
    maximal monotonicity."""
    x = cert.extras
    head = (f"Exact certificate of the piecewise-linear law, {x['n_balls']} balls, "
            f"{x['n_cones']} cones, {x['n_neighbour_pairs']} neighbour pairs:")
    verdict = f"  maximal monotone: {x['maximal_monotone']} — {x['reason']}"
    return "\n".join([head, *(c.line() for c in x["checks"]), verdict])


# --------------------------------------------------------------------------- copositivity
def copositive_2x2(C: FloatArray, tol: float = TOL) -> bool:
    """Exact test for 2 × 2 symmetric C: ``a ≥ 0, c ≥ 0, b + √(ac) ≥ 0``."""
    a, b, c = float(C[0, 0]), float(C[0, 1] + C[1, 0]) / 2, float(C[1, 1])
    return a >= -tol and c >= -tol and b + np.sqrt(max(a, 0.0) * max(c, 0.0)) >= -tol


def copositivity_margins(Cs: FloatArray, vec_tol: float = 1e-9) -> FloatArray:
    """``min {cᵀCc : c ≥ 0, ‖c‖ = 1}`` for each matrix of a stack (k × s × s).

    Exact (Kaplan's criterion): a minimiser with support J solves
    ``C_JJ c_J = μ c_J`` with ``c_J > 0``; at a minimal such support μ is a simple
    eigenvalue, so scanning the eigenpairs of all ``2^s − 1`` principal
    submatrices and keeping the one-signed eigenvectors finds it.  Each accepted
    eigenvector is clipped to the orthant and evaluated, so every candidate is a
    feasible value.  C is copositive iff the margin is ≥ 0.
    """
    Cs = np.asarray(Cs, dtype=float)
    Cs = (Cs + np.swapaxes(Cs, -1, -2)) / 2
    k, s, _ = Cs.shape
    best = np.min(np.diagonal(Cs, axis1=1, axis2=2), axis=1)  # singleton supports
    for size in range(2, s + 1):
        for J in itertools.combinations(range(s), size):
            sub = Cs[:, J][:, :, J]
            _, vecs = np.linalg.eigh(sub)  # columns are eigenvectors
            sign = np.where(vecs.sum(axis=1, keepdims=True) >= 0, 1.0, -1.0)
            v = vecs * sign
            ok = np.all(v >= -vec_tol, axis=1)  # (k, size)
            c = np.clip(v, 0.0, None)
            c = c / np.maximum(np.linalg.norm(c, axis=1, keepdims=True), 1e-300)
            vals = np.einsum("kim,kij,kjm->km", c, sub, c)
            vals = np.where(ok, vals, np.inf).min(axis=1)
            best = np.minimum(best, vals)
    return best


# --------------------------------------------------------------------------- helpers
def _lambda_max(A: FloatArray, B: FloatArray) -> FloatArray:
    """Largest generalized eigenvalue of ``(A_k, B)`` for a stack A, B SPD (Cholesky)."""
    L = np.linalg.cholesky(B)
    Li = np.linalg.inv(L)
    S = Li @ A @ Li.T
    return np.linalg.eigvalsh((S + np.swapaxes(S, -1, -2)) / 2)[..., -1]


def velocity_matrices(Qs: FloatArray, W: FloatArray, G: FloatArray, M: FloatArray) -> FloatArray:
    """Velocity map of each piece: ``A = I + M⁻¹WG⁻¹(Q − I)Wᵀ`` (docs/theory.md §1: Λ = G⁻¹(γ⁺ −
    γ⁻))."""
    n, m = W.shape
    K = np.linalg.solve(M, W) @ np.linalg.inv(G)
    return np.eye(n) + K @ (Qs - np.eye(m)) @ W.T


def neighbour_pairs(ray_ids: NDArray[np.intp]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """Pairs of cones sharing all but one extreme ray, and the ids of the shared rays.

    ``ray_ids`` (n_cones × r) numbers each cone's rays (see :func:`identify_rays`).
    Each facet (a cone's rays minus one) is encoded as one integer; a facet owned
    by exactly two cones makes them neighbours.  Returns ``pairs`` (p × 2) and
    ``shared`` (p × (r−1)).
    """
    ids = np.sort(np.asarray(ray_ids), axis=1)
    k, r = ids.shape
    facets = np.stack([np.delete(ids, j, axis=1) for j in range(r)], axis=1).reshape(k * r, r - 1)
    base = int(ids.max()) + 1
    code = (facets * base ** np.arange(r - 1, dtype=np.int64)).sum(axis=1)
    order = np.argsort(code, kind="stable")
    code_sorted = code[order]
    starts = np.flatnonzero(np.r_[True, code_sorted[1:] != code_sorted[:-1]])
    counts = np.diff(np.r_[starts, len(code)])
    two = starts[counts == 2]
    owner = np.repeat(np.arange(k), r)
    pairs = np.stack([owner[order[two]], owner[order[two + 1]]], axis=1)
    return pairs, facets[order[two]]


def identify_rays(rays: FloatArray, decimals: int = 8) -> tuple[NDArray[np.intp], FloatArray]:
    """Number the distinct extreme rays of a stack of cones (n_cones × r × d, rows = rays).

    Rays are compared after scaling to unit max-norm and rounding to ``decimals``.
    Returns the ids (n_cones × r) and the distinct rays with unit Euclidean norm.
    """
    k, r, d = rays.shape
    flat = rays.reshape(k * r, d)
    keys = np.rint(flat / np.max(np.abs(flat), axis=1, keepdims=True) * 10.0**decimals)
    keys = keys.astype(np.int64)
    index: dict[bytes, int] = {}
    ids = np.array([index.setdefault(row.tobytes(), len(index)) for row in keys])
    first = np.unique(ids, return_index=True)[1]
    uniq = flat[first]
    return ids.reshape(k, r), uniq / np.linalg.norm(uniq, axis=1, keepdims=True)


def table_mass_matrix(table: Any) -> FloatArray:
    """M of a table: its ``M`` (unequal masses) or ``mass·I`` (equal balls, default 1)."""
    if hasattr(table, "M"):
        return np.asarray(table.M, dtype=float)
    return float(getattr(table, "mass", 1.0)) * np.eye(np.shape(table.W)[0])


# --------------------------------------------------------------------------- certificate
SectorCertificate = TableCertificate
"""Another name of :class:`TableCertificate`, kept for code written before the rename."""


def certify_sector_table(table: Any, exact_energy: bool | None = None) -> Certificate:
    """Run every docs/theory.md §7 check on ``table`` (a :class:`~impactqp.tables.SectorTable`).

    The certificate's residuals count, for each check of :data:`TABLE_CHECKS`, the cones
    (neighbour pairs for continuity) that fail it, with tolerance 0: it is ``ok`` when the
    law is admissible on every cone and maximal monotone. Its extras:

    - ``n_balls``, ``n_cones``, ``n_neighbour_pairs``: the table's size (pairs of cones
      sharing a facet, n−2 rays, are checked for continuity);
    - ``cones``: the per-cone margins and verdicts (:class:`ConeCheck`);
    - ``kinematic``, ``kinetic``, ``energetic`` (:class:`CheckResult`): u⁺ ∈ S on every
      cone, γ⁺ ≥ 0, Λ ≥ 0 and no energy gain (docs/theory.md §2); ``admissible``: all
      three;
    - ``continuity``: neighbouring cones agree on their shared rays;
    - ``non_expansive``, ``velocity_non_expansive``: every piece is non-expansive in G⁻¹
      (contact velocities) and in M (velocities);
    - ``checks``: the six, in report order (:func:`table_report`);
    - ``maximal_monotone``: continuity and non-expansiveness together (docs/theory.md §6);
      ``reason``: the failed check and cone, or why the property holds.

    Parameters
    ----------
    table : SectorTable
    exact_energy : bool, optional
        Compute the exact energetic margin (the minimum over the cone, by
        :func:`copositivity_margins`) for every cone.  Default: only for
        n_balls <= 6.  Otherwise cones whose energy matrix is positive semidefinite
        are certified by ``λ_min ≥ 0`` (PSD ⇒ copositive; the margin reported is
        then the lower bound ``λ_min``) and only the others are enumerated, which
        keeps 8 balls (40 320 cones) to a few seconds.  The verdicts are exact
        either way; only the reported margins of PSD cones differ.
    """
    cones = table.cones
    labels = [c.label for c in cones]
    G = np.asarray(table.G, dtype=float)
    W = np.asarray(table.W, dtype=float)
    M = table_mass_matrix(table)
    Gi = np.linalg.inv(G)
    d = G.shape[0]
    Qs = np.stack([c.Q for c in cones])
    Rs = np.stack([c.rays.T for c in cones])  # rays as columns
    gscale = TOL * max(1.0, float(np.linalg.norm(Gi, 2)))

    kin = (Qs @ Rs).min(axis=(1, 2))
    lam = (Gi @ (Qs - np.eye(d)) @ Rs).min(axis=(1, 2))
    E = np.swapaxes(Rs, 1, 2) @ (Gi - np.swapaxes(Qs, 1, 2) @ Gi @ Qs) @ Rs
    exact = exact_energy if exact_energy is not None else d <= 5
    if exact:
        ener = copositivity_margins(E)
    else:
        ener = np.linalg.eigvalsh((E + np.swapaxes(E, 1, 2)) / 2)[:, 0]  # lower bound
        bad = ener < -gscale
        if bad.any():
            ener[bad] = copositivity_margins(E[bad])
    ener_ok = ener >= -gscale
    if d == 2:  # exact closed form, cross-checked against the general margin
        ener_ok = np.array([copositive_2x2(C, gscale) for C in E])
    expa = _lambda_max(np.swapaxes(Qs, 1, 2) @ Gi @ Qs, Gi)
    As = velocity_matrices(Qs, W, G, M)
    vnorm = np.sqrt(np.maximum(_lambda_max(np.swapaxes(As, 1, 2) @ M @ As, M), 0.0))

    ray_ids, unit = identify_rays(Rs.transpose(0, 2, 1))
    pairs, shared = neighbour_pairs(ray_ids)
    if len(pairs) and shared.shape[1]:
        R_sh = unit[shared]  # (p, r−1, d)
        jumps = np.abs(np.einsum("pij,psj->psi", Qs[pairs[:, 0]] - Qs[pairs[:, 1]], R_sh))
        jump = jumps.max(axis=(1, 2))
    else:
        jump = np.zeros(len(pairs))  # n = 2: neighbours share only the origin
    qscale = TOL * max(1.0, float(np.abs(Qs).max()))

    checks = [ConeCheck(labels[i], float(kin[i]), float(lam[i]), float(ener[i]),
                        float(expa[i]), float(vnorm[i]), bool(kin[i] >= -TOL),
                        bool(lam[i] >= -gscale), bool(ener_ok[i]),
                        bool(expa[i] <= 1 + TOL), bool(vnorm[i] <= 1 + TOL))
              for i in range(len(cones))]

    def worst_min(name: str, vals: FloatArray, ok: NDArray[np.bool_], meaning: str) -> CheckResult:
        i = int(np.argmin(vals if ok.all() else np.where(ok, np.inf, vals)))  # worst failing
        return CheckResult(name, bool(ok.all()), float(vals.min()), labels[i], meaning)

    def worst_max(name: str, vals: FloatArray, ok: NDArray[np.bool_], meaning: str) -> CheckResult:
        i = int(np.argmax(vals if ok.all() else np.where(ok, -np.inf, vals)))
        return CheckResult(name, bool(ok.all()), float(vals.max()), labels[i], meaning)

    kinematic = worst_min("kinematic", kin, kin >= -TOL, "min Q r")
    kinetic = worst_min("kinetic", lam, lam >= -gscale, "min Λ")
    energetic = worst_min("energetic", ener, ener_ok,
                          "min on cone of γᵀ(G⁻¹−QᵀG⁻¹Q)γ" if exact else
                          "lower bound (λ_min, PSD ⇒ copositive) of γᵀ(G⁻¹−QᵀG⁻¹Q)γ")
    non_exp = worst_max("non-expansive (G⁻¹)", expa, expa <= 1 + TOL, "max λ_max(GQᵀG⁻¹Q)")
    vel = worst_max("non-expansive (M)", vnorm, vnorm <= 1 + TOL, "max ‖u⁻ ↦ u⁺‖_M")
    pa, pb = ("-", "-")
    if len(pairs):
        p = int(np.argmax(jump))
        pa, pb = labels[pairs[p, 0]], labels[pairs[p, 1]]
    jmax = float(jump.max()) if len(pairs) else 0.0
    continuity = CheckResult("continuity", jmax <= qscale, jmax, f"{pa} | {pb}",
                             "max |Q_a r − Q_b r|")

    mm = continuity.passed and non_exp.passed and vel.passed
    if not continuity.passed:
        reason = (f"discontinuous between cones '{pa}' and '{pb}' "
                  f"(jump {jmax:.3g} on a shared ray)")
    elif not non_exp.passed:
        reason = (f"piece on cone '{non_exp.worst}' expands the G⁻¹ norm "
                  f"(λ_max = {non_exp.margin:.6g})")
    elif not vel.passed:
        reason = (f"velocity map on cone '{vel.worst}' expands the M norm "
                  f"(‖A‖_M = {vel.margin:.6g})")
    else:
        reason = (f"continuous across all {len(pairs)} neighbour pairs and every piece is "
                  "non-expansive in G⁻¹ and M, so the law is non-expansive, hence maximal "
                  "monotone")
    for c in (kinematic, kinetic, energetic):
        if not c.passed:
            reason += f"; note: {c.name} consistency fails on cone '{c.worst}'"
    passing = {"kinematic": kin >= -TOL, "kinetic": lam >= -gscale, "energetic": ener_ok,
               "continuity": jump <= qscale, "non_expansive": expa <= 1 + TOL,
               "velocity_non_expansive": vnorm <= 1 + TOL}  # NaN fails each
    failing = {k: int(np.sum(~np.asarray(v, dtype=bool))) for k, v in passing.items()}
    results = {"kinematic": kinematic, "kinetic": kinetic, "energetic": energetic,
               "continuity": continuity, "non_expansive": non_exp,
               "velocity_non_expansive": vel}
    extras = {"n_balls": int(table.n_balls), "n_cones": len(cones),
              "n_neighbour_pairs": len(pairs), "cones": tuple(checks), **results,
              "checks": tuple(results.values()),
              "admissible": kinematic.passed and kinetic.passed and energetic.passed,
              "maximal_monotone": mm, "reason": reason}
    return Certificate({TABLE_CHECKS[k]: v for k, v in failing.items()}, 0.0,
                       names=tuple(TABLE_CHECKS.values()), extras=extras)
